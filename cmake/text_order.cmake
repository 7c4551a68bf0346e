# LL_TEXT_ORDER_SCRIPT: the toolchain's own default linker script for LL_MCU with the input
# section order of cmake/text_order.ld put in front of its "*(.text.*)". Every AVR image links
# with it (LL_TARGET_LINK_FLAGS), so hot callees sit within rcall range of their callers.
set(LL_TEXT_ORDER ${CMAKE_CURRENT_LIST_DIR}/text_order.ld)
set_property(DIRECTORY ${PROJECT_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${LL_TEXT_ORDER})
execute_process(COMMAND ${CMAKE_CXX_COMPILER} -mmcu=${LL_MCU} -print-multi-directory
                OUTPUT_VARIABLE ll_emulation OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT ll_emulation MATCHES "^avr[a-z0-9]+$")
  message(FATAL_ERROR "text_order: no linker emulation for ${LL_MCU} ('${ll_emulation}')")
endif()
execute_process(COMMAND ${CMAKE_LINKER} --verbose -m${ll_emulation}
                OUTPUT_VARIABLE ll_verbose RESULT_VARIABLE rc)
# The script is printed between two lines of '='.
if(NOT rc EQUAL 0 OR NOT ll_verbose MATCHES "\n=+\n(.*)\n=+\n")
  message(FATAL_ERROR "text_order: ${CMAKE_LINKER} --verbose -m${ll_emulation} gave no script")
endif()
set(ll_script "${CMAKE_MATCH_1}")
set(ll_anchor "\n     *(.text.*)\n")
string(FIND "${ll_script}" "${ll_anchor}" first)
string(FIND "${ll_script}" "${ll_anchor}" last REVERSE)
if(first EQUAL -1 OR NOT first EQUAL last)
  message(FATAL_ERROR "text_order: the default script of ${ll_emulation} has not exactly one "
                      "'*(.text.*)' line")
endif()
file(READ ${LL_TEXT_ORDER} ll_order)
string(REPLACE "${ll_anchor}" "\n${ll_order}${ll_anchor}" ll_script "${ll_script}")
set(LL_TEXT_ORDER_SCRIPT ${CMAKE_BINARY_DIR}/ll_${ll_emulation}.x)
# Rewritten only when it changes: an unchanged script relinks nothing.
file(WRITE ${LL_TEXT_ORDER_SCRIPT}.tmp "${ll_script}\n")
configure_file(${LL_TEXT_ORDER_SCRIPT}.tmp ${LL_TEXT_ORDER_SCRIPT} COPYONLY)
