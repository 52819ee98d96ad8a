# Usage: cmake -DCMD="prog;arg;..." -DEXPECT=<regex> -P expect_failure.cmake
# Passes when the command exits non-zero and its output matches EXPECT.
execute_process(COMMAND ${CMD} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "expected a failure, got exit 0\n${out}${err}")
endif()
if(NOT "${out}${err}" MATCHES "${EXPECT}")
  message(FATAL_ERROR "exit ${rc}, but the message does not match '${EXPECT}':\n${out}${err}")
endif()
message(STATUS "exit ${rc}: ${err}")
