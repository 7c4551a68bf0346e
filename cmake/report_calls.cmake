# Prints how many calls and jumps of an image --relax left 4 bytes long (target farther than
# 4 KiB) against the 2-byte rcall/rjmp: the measure of cmake/text_order.ld.
# Usage: cmake -DOBJDUMP=avr-objdump -DFILE=<elf> -P report_calls.cmake
execute_process(COMMAND ${OBJDUMP} -d ${FILE} OUTPUT_VARIABLE dis RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${OBJDUMP} failed on ${FILE}")
endif()
foreach(op call rcall jmp rjmp)
  string(REGEX MATCHALL "\t${op}\t" hits "${dis}")
  list(LENGTH hits n_${op})
endforeach()
math(EXPR long "${n_call} + ${n_jmp}")
message(STATUS "${FILE}: ${long} long call/jmp (${n_call} call, ${n_jmp} jmp), "
               "${n_rcall} rcall, ${n_rjmp} rjmp")
