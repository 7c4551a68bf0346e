// Interposition on simavr's per-register callbacks (avr_t::io[]), so that harness code can run
// around simavr's own handler for an I/O register: before it, after it, or with a changed value.
//
// Why not avr_register_io_write(): when a register already has a handler, simavr 1.6 chains the
// new one *after* it through a small shared table (4 slots). The datasheet corrections need to
// see the state before simavr's handler runs (e.g. "was the timer stopped?"), or to change the
// value it receives (SBI on PINx), which only interposition allows. The original callback and
// its parameter are public fields of avr_t, so this stays within simavr's public headers.
#pragma once

#include <stdint.h>

#include <functional>
#include <vector>

extern "C" {
#include <sim_avr.h>
}

namespace ll {
namespace sim {

class IoHooks {
  public:
    /// Calls the rest of the chain for a write (later hooks, then simavr's handler).
    class WriteNext {
      public:
        void operator()(uint8_t value) const;

      private:
        friend class IoHooks;
        WriteNext(IoHooks* hooks, uint16_t addr, size_t index)
            : hooks_(hooks), addr_(addr), index_(index) {}
        IoHooks* hooks_;
        uint16_t addr_;
        size_t index_;
    };
    /// Calls the rest of the chain for a read; returns the value the CPU will see.
    class ReadNext {
      public:
        uint8_t operator()() const;

      private:
        friend class IoHooks;
        ReadNext(IoHooks* hooks, uint16_t addr, size_t index)
            : hooks_(hooks), addr_(addr), index_(index) {}
        IoHooks* hooks_;
        uint16_t addr_;
        size_t index_;
    };

    /// A write hook gets the data-space address, the value the CPU writes and `next`; it must
    /// call next(value) exactly once unless it deliberately swallows the write.
    using WriteHook = std::function<void(uint16_t addr, uint8_t value, const WriteNext& next)>;
    using ReadHook = std::function<uint8_t(uint16_t addr, const ReadNext& next)>;

    explicit IoHooks(avr_t* avr);
    ~IoHooks();
    IoHooks(const IoHooks&) = delete;
    IoHooks& operator=(const IoHooks&) = delete;

    /// Adds a hook on writes to `addr` (data-space address, 0x20..). Hooks added first run first.
    void on_write(uint16_t addr, WriteHook hook);
    void on_read(uint16_t addr, ReadHook hook);

    /// Writes through simavr's own handler only (no hook), as the CPU would without the harness.
    void write_original(uint16_t addr, uint8_t value);
    /// Reads through simavr's own handler only (it may have side effects, e.g. UDR0).
    uint8_t read_original(uint16_t addr);

  private:
    struct Slot {
        bool installed = false;
        avr_io_write_t orig_write = nullptr;
        void* orig_write_param = nullptr;
        avr_io_read_t orig_read = nullptr;
        void* orig_read_param = nullptr;
        bool write_hooked = false;
        bool read_hooked = false;
        std::vector<WriteHook> writes;
        std::vector<ReadHook> reads;
    };

    static void write_trampoline(avr_t* avr, avr_io_addr_t addr, uint8_t v, void* param);
    static uint8_t read_trampoline(avr_t* avr, avr_io_addr_t addr, void* param);
    void dispatch_write(uint16_t addr, size_t index, uint8_t value);
    uint8_t dispatch_read(uint16_t addr, size_t index);
    Slot& slot(uint16_t addr);

    avr_t* avr_;
    std::vector<Slot> slots_; ///< indexed by I/O number (data address - 32)
};

} // namespace sim
} // namespace ll
