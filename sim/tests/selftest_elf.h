// Locating the self-test firmwares (built by the avr preset) from the host tests.
#pragma once

#include <sys/stat.h>

#include <string>

#include <gtest/gtest.h>

#include "harness.h"

namespace ll {
namespace sim {
namespace test {

/// build/avr/sim/selftest/<name>.elf, from the LL_AVR_BUILD_DIR cache variable.
inline std::string selftest_elf(const std::string& name) {
    return std::string(LLSIM_SELFTEST_DIR) + "/" + name + ".elf";
}

inline bool exists(const std::string& path) {
    struct stat st;
    return stat(path.c_str(), &st) == 0;
}

inline Options options(const std::string& name, const Corrections& c = Corrections::all()) {
    Options o;
    o.elf = selftest_elf(name);
    o.corrections = c;
    return o;
}

inline Corrections all_but(bool Corrections::*member) {
    Corrections c = Corrections::all();
    c.*member = false;
    return c;
}

} // namespace test
} // namespace sim
} // namespace ll

/// Fails the test (never skips) when the avr preset has not built the self-test firmware.
#define REQUIRE_SELFTEST(name)                                                                     \
    ASSERT_TRUE(::ll::sim::test::exists(::ll::sim::test::selftest_elf(name)))                      \
        << "missing " << ::ll::sim::test::selftest_elf(name)                                       \
        << ": build the firmware first (cmake --preset avr && cmake --build --preset avr), or "    \
           "point LL_AVR_BUILD_DIR at the AVR build directory"
