// llsegcost: what producing one macro segment costs on the ATmega328P (docs/motion.md, "Compute
// windows"). Runs llsegcost.elf (tools/avr/segcost_app.cpp: the step generator alone, no
// protocol, no planner) in simavr and times every call of the step generator's functions with
// the call profiler of tools/simjob.h (exact cycles, interrupts taken out).
//
//   build/host/tools/llsegcost [--elf build/avr/firmware/llsegcost.elf]
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "harness.h"
#include "simjob.h"

#ifndef LLSEGCOST_ELF
#define LLSEGCOST_ELF "build/avr/firmware/llsegcost.elf"
#endif

using ll::sim::Sim;
using ll::tools::Profiler;

int main(int argc, char** argv) {
    std::string elf = LLSEGCOST_ELF;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--elf") && i + 1 < argc) {
            elf = argv[++i];
        } else {
            std::fprintf(stderr, "usage: llsegcost [--elf FILE]\n");
            return 2;
        }
    }
    const std::vector<std::pair<std::string, std::string>> fns = {
        {"_ZN2ll7StepGen4fillERNS_7RunRingILh16EEE", "StepGen::fill"},
        {"_ZN2ll12line_advanceERKNS_12LineGeometryERNS_10LineCursorEhPh", "line_advance"},
        {"_ZN2ll11micro_splitEPKhhPNS_8MicroRunE", "micro_split"},
        {"_ZN2ll7StepGen8delta_atEm", "StepGen::delta_at"},
        {"_ZN2ll9profile_aERKNS_7ProfileEm", "profile_a"},
        {"_ZN2ll11SqrtTracker4seekEm", "SqrtTracker::seek"},
        {"_ZN2ll7StepGen4emitERNS_7RunRingILh16EEEhhhm", "StepGen::emit"},
        {"_ZN2ll7StepGen12horizon_fullERKNS_7RunRingILh16EEE", "StepGen::horizon_full"},
        {"_ZN2ll7mul_shrEmmh", "mul_shr"},
        {"__udivmodsi4", "__udivmodsi4 (32-bit division)"},
        {"_ZN2ll7StepGen5beginERKNS_8MoveSpecE", "StepGen::begin"},
    };
    const char* names[] = {"", "X 10 mm at 4,000 steps/s", "X 10 mm at 30,000 steps/s",
                           "X 10 mm at 100,000 steps/s", "XYZ 10 mm each at 30,000 steps/s"};
    Sim sim(elf);
    std::vector<std::string> syms;
    for (const auto& f : fns) syms.push_back(f.first);
    Profiler prof(sim, syms);
    const uint16_t kGpior0 = 0x3E;
    sim.watch_register(kGpior0);
    bool done = sim.run_until(
        [&] {
            prof.step();
            return sim.peek(kGpior0) == 0xFF;
        },
        16000000ull * 600);
    if (!done) {
        std::fprintf(stderr, "llsegcost: the image did not finish\n");
        return 1;
    }
    // Case boundaries from the GPIOR0 writes.
    std::vector<uint64_t> bound(6, 0);
    for (const auto& w : sim.register_writes()) {
        if (w.value >= 1 && w.value <= 4) bound[w.value] = w.cycle;
        if (w.value == 0xFF) bound[5] = w.cycle;
    }
    std::printf("llsegcost: %s, 1000 steps/mm, 2000 mm/s^2, rest to rest, min period 152\n\n",
                elf.c_str());
    for (int c = 1; c <= 4; ++c) {
        std::vector<uint64_t> cyc(fns.size(), 0);
        std::vector<size_t> calls(fns.size(), 0);
        const auto& all = prof.calls();
        for (const auto& call : all) {
            if (!call.end || call.start < bound[c] || call.start >= bound[c + 1]) continue;
            bool nested = false;
            for (int p = call.parent; p >= 0; p = all[static_cast<size_t>(p)].parent) {
                if (all[static_cast<size_t>(p)].fn == call.fn) nested = true;
            }
            if (nested) continue;
            ++calls[static_cast<size_t>(call.fn)];
            cyc[static_cast<size_t>(call.fn)] += prof.own_cycles(call);
        }
        const size_t segments = calls[1]; // one line_advance() per macro segment
        std::printf("### %s: %zu segments\n\n| function (inclusive) | calls | cycles/call | "
                    "cycles/segment |\n|---|---|---|---|\n",
                    names[c], segments);
        for (size_t i = 0; i < fns.size(); ++i) {
            if (!calls[i]) continue;
            std::printf("| %s | %zu | %.0f | %.0f |\n", fns[i].second.c_str(), calls[i],
                        static_cast<double>(cyc[i]) / static_cast<double>(calls[i]),
                        static_cast<double>(cyc[i]) / static_cast<double>(segments));
        }
        std::printf("\n");
    }
    return 0;
}
