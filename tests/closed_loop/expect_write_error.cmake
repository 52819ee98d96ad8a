# Usage: cmake -DSIL=<pmstep-sil> -DOUT=<folder> -P expect_write_error.cmake
# summary.json is made a link to /dev/full: every write to it fails with ENOSPC. The SIL
# must say so and exit non-zero, not report success with an empty summary.
if(NOT EXISTS /dev/full)
  message(FATAL_ERROR "/dev/full is missing: cannot provoke a write error")
endif()
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
file(CREATE_LINK /dev/full ${OUT}/summary.json SYMBOLIC)
execute_process(COMMAND ${SIL} --quiet --no-csv --out ${OUT} --set run.duration_s=0.01
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "expected a failure, got exit 0\n${out}${err}")
endif()
if(NOT err MATCHES "error writing '.*summary.json'")
  message(FATAL_ERROR "exit ${rc}, but no write error reported:\n${out}${err}")
endif()
message(STATUS "exit ${rc}: ${err}")
