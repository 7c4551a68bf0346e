#include "io_hooks.h"

#include <stdexcept>

namespace ll {
namespace sim {

IoHooks::IoHooks(avr_t* avr) : avr_(avr), slots_(MAX_IOs) {}

IoHooks::~IoHooks() {
    // Give simavr its own callbacks back, so the avr_t stays usable without this object.
    for (size_t io = 0; io < slots_.size(); ++io) {
        Slot& s = slots_[io];
        if (s.write_hooked) {
            avr_->io[io].w.c = s.orig_write;
            avr_->io[io].w.param = s.orig_write_param;
        }
        if (s.read_hooked) {
            avr_->io[io].r.c = s.orig_read;
            avr_->io[io].r.param = s.orig_read_param;
        }
    }
}

IoHooks::Slot& IoHooks::slot(uint16_t addr) {
    if (addr < 32 || static_cast<size_t>(addr - 32) >= slots_.size())
        throw std::out_of_range("IoHooks: not an I/O register address");
    return slots_[static_cast<size_t>(addr - 32)];
}

void IoHooks::on_write(uint16_t addr, WriteHook hook) {
    Slot& s = slot(addr);
    const size_t io = static_cast<size_t>(addr - 32);
    if (!s.write_hooked) {
        s.orig_write = avr_->io[io].w.c;
        s.orig_write_param = avr_->io[io].w.param;
        avr_->io[io].w.c = &IoHooks::write_trampoline;
        avr_->io[io].w.param = this;
        s.write_hooked = true;
    }
    s.writes.push_back(std::move(hook));
}

void IoHooks::on_read(uint16_t addr, ReadHook hook) {
    Slot& s = slot(addr);
    const size_t io = static_cast<size_t>(addr - 32);
    if (!s.read_hooked) {
        s.orig_read = avr_->io[io].r.c;
        s.orig_read_param = avr_->io[io].r.param;
        avr_->io[io].r.c = &IoHooks::read_trampoline;
        avr_->io[io].r.param = this;
        s.read_hooked = true;
    }
    s.reads.push_back(std::move(hook));
}

void IoHooks::write_trampoline(avr_t*, avr_io_addr_t addr, uint8_t v, void* param) {
    static_cast<IoHooks*>(param)->dispatch_write(addr, 0, v);
}

uint8_t IoHooks::read_trampoline(avr_t*, avr_io_addr_t addr, void* param) {
    return static_cast<IoHooks*>(param)->dispatch_read(addr, 0);
}

void IoHooks::dispatch_write(uint16_t addr, size_t index, uint8_t value) {
    Slot& s = slots_[static_cast<size_t>(addr - 32)];
    if (index < s.writes.size()) {
        s.writes[index](addr, value, WriteNext(this, addr, index + 1));
        return;
    }
    write_original(addr, value);
}

uint8_t IoHooks::dispatch_read(uint16_t addr, size_t index) {
    Slot& s = slots_[static_cast<size_t>(addr - 32)];
    if (index < s.reads.size()) return s.reads[index](addr, ReadNext(this, addr, index + 1));
    return read_original(addr);
}

void IoHooks::write_original(uint16_t addr, uint8_t value) {
    const Slot& s = slot(addr);
    const size_t io = static_cast<size_t>(addr - 32);
    avr_io_write_t fn = s.write_hooked ? s.orig_write : avr_->io[io].w.c;
    void* param = s.write_hooked ? s.orig_write_param : avr_->io[io].w.param;
    if (fn)
        fn(avr_, addr, value, param);
    else
        avr_core_watch_write(avr_, addr, value); // what the core does for a plain register
}

uint8_t IoHooks::read_original(uint16_t addr) {
    const Slot& s = slot(addr);
    const size_t io = static_cast<size_t>(addr - 32);
    avr_io_read_t fn = s.read_hooked ? s.orig_read : avr_->io[io].r.c;
    void* param = s.read_hooked ? s.orig_read_param : avr_->io[io].r.param;
    if (fn) return fn(avr_, addr, param);
    return avr_core_watch_read(avr_, addr);
}

void IoHooks::WriteNext::operator()(uint8_t value) const {
    hooks_->dispatch_write(addr_, index_, value);
}

uint8_t IoHooks::ReadNext::operator()() const {
    return hooks_->dispatch_read(addr_, index_);
}

} // namespace sim
} // namespace ll
