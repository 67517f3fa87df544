# Checks that a generated file of the repository is what the program prints now:
#   cmake -DSACCADE=<saccade binary> "-DARGS=gui --protocol-markdown" -DROOT=<repository>
#         -DFILE=docs/gui-protocol.md -P tests/docs/check_generated.cmake
# Fails with the first line that differs and the command that brings the file up to date.
cmake_minimum_required(VERSION 3.25)
if(NOT SACCADE OR NOT ARGS OR NOT ROOT OR NOT FILE)
  message(FATAL_ERROR "usage: cmake -DSACCADE=<saccade> -DARGS=<arguments> -DROOT=<repository> "
                      "-DFILE=<file in it> -P check_generated.cmake")
endif()
set(_command "saccade ${ARGS}")
separate_arguments(_args UNIX_COMMAND "${ARGS}")
execute_process(COMMAND "${SACCADE}" ${_args} OUTPUT_VARIABLE _generated RESULT_VARIABLE _rc)
if(NOT _rc EQUAL 0)
  message(FATAL_ERROR "${_command} exited with ${_rc}")
endif()
file(READ "${ROOT}/${FILE}" _committed)
if(NOT _generated STREQUAL _committed)
  # The first line that differs, to say where (semicolons and brackets, which CMake's lists
  # read, replaced first).
  foreach(_text _generated _committed)
    string(REPLACE ";" "," ${_text} "${${_text}}")
    string(REPLACE "[" "<" ${_text} "${${_text}}")
    string(REPLACE "]" ">" ${_text} "${${_text}}")
  endforeach()
  string(REPLACE "\n" ";" _new "${_generated}")
  string(REPLACE "\n" ";" _old "${_committed}")
  list(LENGTH _new _n_new)
  list(LENGTH _old _n_old)
  set(_line 0)
  while(_line LESS _n_new AND _line LESS _n_old)
    list(GET _new ${_line} _a)
    list(GET _old ${_line} _b)
    if(NOT _a STREQUAL _b)
      break()
    endif()
    math(EXPR _line "${_line} + 1")
  endwhile()
  math(EXPR _shown "${_line} + 1")
  message(FATAL_ERROR "${FILE} differs from the code from line ${_shown} on: run\n"
                      "  ${_command} > ${FILE}")
endif()
message(STATUS "${FILE} matches the code")
