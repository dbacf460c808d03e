# Helpers of the package tests' scripts (run_*_test.cmake), which run as cmake -P.

# require_definitions(SCRIPT VAR...): fails unless every VAR was given with -DVAR=...
function(require_definitions script)
  foreach(var ${ARGN})
    if(NOT DEFINED ${var})
      message(FATAL_ERROR "${script}: -D${var}=... is required")
    endif()
  endforeach()
endfunction()

# step(WHAT [INPUT FILE] COMMAND...): runs the command (standard input from FILE), fails the test
# on a non-zero exit with what it printed, and leaves its standard output in step_output.
function(step what)
  cmake_parse_arguments(S "" "INPUT" "" ${ARGN})
  set(input)
  if(S_INPUT)
    set(input INPUT_FILE ${S_INPUT})
  endif()
  message(STATUS "${what}")
  execute_process(COMMAND ${S_UNPARSED_ARGUMENTS} ${input} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}\n${err}")
  endif()
  set(step_output "${out}" PARENT_SCOPE)
endfunction()
