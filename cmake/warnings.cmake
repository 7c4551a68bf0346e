# Warnings are errors on both compilers (g++ for the host, avr-gcc 5.4 for the chip).
set(LL_WARNINGS -Wall -Wextra -Wshadow -Werror)
# The portable core and the firmware also refuse silent sign changes.
set(LL_STRICT_WARNINGS ${LL_WARNINGS} -Wsign-conversion -Wdouble-promotion)
if(LL_AVR)
  set(LL_TARGET_FLAGS -fno-exceptions -fno-rtti -ffunction-sections -fdata-sections
      -fno-threadsafe-statics -Os)
else()
  set(LL_TARGET_FLAGS)
endif()
