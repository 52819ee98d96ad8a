# Processor in the loop, replay: the firmware on QEMU's emulated Cortex-M4 replays the
# SIL's record through pmstep_step(), then pil-compare checks its outputs against the
# host's, word by word. -icount shift=0 (one instruction = 1 ns of virtual time) makes
# the image's SysTick readings count instructions (its cost file, checked by pil.cost).
# Usage: cmake -DQEMU= -DIMAGE= -DRECORD= -DOUTPUTS= -DCOST= -DCOMPARE= -P run_replay.cmake
cmake_minimum_required(VERSION 3.20)
foreach(var QEMU IMAGE RECORD OUTPUTS COST COMPARE)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_replay.cmake: -D${var}= missing")
  endif()
endforeach()
foreach(path ${RECORD} ${OUTPUTS} ${COST})
  if(path MATCHES ",")
    message(FATAL_ERROR "run_replay.cmake: '${path}' contains a comma, which QEMU's -semihosting-config cannot pass")
  endif()
endforeach()
file(REMOVE ${OUTPUTS} ${COST})
execute_process(
  COMMAND ${QEMU} -M mps2-an386 -cpu cortex-m4 -nographic -monitor none -serial none -icount shift=0
          -semihosting-config enable=on,target=native,arg=pil-replay,arg=${RECORD},arg=${OUTPUTS},arg=${COST}
          -kernel ${IMAGE}
  RESULT_VARIABLE rc TIMEOUT 300)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the replay on QEMU failed (exit status ${rc})")
endif()
execute_process(COMMAND ${COMPARE} ${RECORD} ${OUTPUTS} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the target's outputs differ from the host's (see above)")
endif()
