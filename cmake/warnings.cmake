# Warnings are errors on both compilers (g++ for the host, avr-gcc 5.4 for the chip).
set(LL_WARNINGS -Wall -Wextra -Wshadow -Werror)
# The portable core and the firmware also refuse silent sign changes.
set(LL_STRICT_WARNINGS ${LL_WARNINGS} -Wsign-conversion -Wdouble-promotion)
if(LL_AVR)
  # -mstrict-X and -fno-move-loop-invariants: 1.1 % smaller code with avr-gcc 5.4 (fewer
  # pointer reloads, no loop invariants spilled to the stack).
  set(LL_TARGET_FLAGS -fno-exceptions -fno-rtti -ffunction-sections -fdata-sections
      -fno-threadsafe-statics -Os -mstrict-X -fno-move-loop-invariants -mrelax)
  # --relax: the linker turns call/jmp into rcall/rjmp where the target is within 4 KiB
  # (2 bytes and 1 cycle less each): 600 B of a 45 KB image.
  # The code order of cmake/text_order.ld puts hot callees within rcall range: 418 B.
  include(${CMAKE_CURRENT_LIST_DIR}/text_order.cmake)
  set(LL_TARGET_LINK_FLAGS -Wl,--gc-sections -mrelax -Wl,-T,${LL_TEXT_ORDER_SCRIPT})
else()
  set(LL_TARGET_FLAGS)
  set(LL_TARGET_LINK_FLAGS)
endif()
