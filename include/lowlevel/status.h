// GRBL 1.1 response codes (`error:N`, doc/csv/error_codes_en_US.csv) and alarm codes (`ALARM:N`).
// Every module that answers a line returns one of these; 0 means `ok`.
#pragma once

#include <stdint.h>

namespace ll {
namespace status {

enum : uint8_t {
    kOk = 0,
    kExpectedCommandLetter = 1, ///< a word does not start with A-Z
    kBadNumberFormat = 2,       ///< missing value, or a value too large for its fixed-point field
    kInvalidStatement = 3,      ///< unknown or malformed `$` command, setting out of range
    kNegativeValue = 4,         ///< negative (or zero where a positive value is required)
    kStepPulseMin = 6,          ///< $0 below 3 us
    kSettingReadFail = 7,       ///< EEPROM blank or corrupt: defaults restored
    kIdleError = 8,             ///< `$` command that needs the machine idle
    kGcodeLock = 9,             ///< G-code refused while in alarm
    kOverflow = 11,             ///< line too long, or bytes of it lost in the receive buffer
    kUnsupportedCommand = 20,   ///< unsupported word or command, or a non-ASCII byte in the line
    kModalGroupViolation = 21,
    kUndefinedFeedRate = 22,
    kCommandValueNotInteger = 23,
    kAxisCommandConflict = 24,
    kWordRepeated = 25,
    kNoAxisWords = 26,
    kInvalidLineNumber = 27,
    kValueWordMissing = 28,
    kUnsupportedCoordSys = 29,
    kG53InvalidMotionMode = 30,
    kAxisWordsExist = 31,
    kNoAxisWordsInPlane = 32,
    kInvalidTarget = 33, ///< also: a target that does not fit the position range
    kArcRadiusError = 34,
    kNoOffsetsInPlane = 35,
    kUnusedWords = 36,
    kMaxValueExceeded = 38, ///< T above 255
};

} // namespace status

namespace alarm {
enum : uint8_t {
    kHardLimit = 1,
    kSoftLimit = 2,
    kAbortCycle = 3, ///< reset while moving: position may be lost
};
} // namespace alarm

} // namespace ll
