# Processor in the loop, closed loop: plant and core both on QEMU's emulated Cortex-M4,
# the shortened paper scenario; pil-summary-compare checks its summary against the host
# SIL's run of the same scenario and settings.
# Usage: cmake -DQEMU= -DIMAGE= -DDURATION= -DSUBSTEPS= -DHOST_SUMMARY= -DTARGET_SUMMARY= -DCOMPARE=
#              -P run_closed_loop.cmake
cmake_minimum_required(VERSION 3.20)
foreach(var QEMU IMAGE DURATION SUBSTEPS HOST_SUMMARY TARGET_SUMMARY COMPARE)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_closed_loop.cmake: -D${var}= missing")
  endif()
endforeach()
if(TARGET_SUMMARY MATCHES ",")
  message(FATAL_ERROR "run_closed_loop.cmake: '${TARGET_SUMMARY}' contains a comma, which QEMU cannot pass")
endif()
file(REMOVE ${TARGET_SUMMARY})
execute_process(
  COMMAND ${QEMU} -M mps2-an386 -cpu cortex-m4 -nographic -monitor none -serial none
          -semihosting-config enable=on,target=native,arg=pil-closed-loop,arg=--duration,arg=${DURATION},arg=--substeps,arg=${SUBSTEPS},arg=--summary,arg=${TARGET_SUMMARY}
          -kernel ${IMAGE}
  OUTPUT_QUIET RESULT_VARIABLE rc TIMEOUT 300)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the closed loop on QEMU failed (exit status ${rc}; 3 = a fault latched)")
endif()
execute_process(COMMAND ${COMPARE} ${HOST_SUMMARY} ${TARGET_SUMMARY} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the target's closed loop does not match the host SIL's within the tolerances")
endif()
