# Runs EXE with ARGS and passes only if it exits non-zero with "error" on stderr (and was not killed).
execute_process(COMMAND ${EXE} ${ARGS} RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(rc EQUAL 0 OR NOT rc MATCHES "^[0-9]+$" OR rc GREATER 127)
  message(FATAL_ERROR "expected a clean non-zero exit, got '${rc}'")
endif()
if(NOT err MATCHES "error")
  message(FATAL_ERROR "expected an error message on stderr, got '${err}'")
endif()
