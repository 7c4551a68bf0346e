# Fails when an AVR object or image refers to a floating-point routine (soft-float or libm).
# Usage: cmake -DNM=avr-nm -DFILE=<archive or elf> -DWHAT=<label> -P check_no_float.cmake
execute_process(COMMAND ${NM} ${FILE} OUTPUT_VARIABLE syms RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${NM} failed on ${FILE}")
endif()
string(REGEX MATCHALL
  "[ \t](__(add|sub|mul|div|neg|cmp|eq|ne|lt|le|gt|ge|unord|pow|extend|trunc)[sd]f[0-9]*|__fix(uns)?[sd]f[a-z]*|__float(un)?[a-z]*[sd]f|__fp_[a-z_]*|sqrtf?|sinf?|cosf?|atan2f?|floorf?|ceilf?|fabsf?|powf?|roundf?|lroundf?)\n"
  hits "${syms}")
if(hits)
  list(REMOVE_DUPLICATES hits)
  string(REPLACE "\n" "" hits "${hits}")
  message(FATAL_ERROR "${WHAT}: floating-point routines referenced: ${hits}\n"
                      "Low Level's motion code is integer-only (seed §6, §7.2, §8.2).")
endif()
message(STATUS "${WHAT}: no floating-point routine referenced")
