# Checks that docs/components.md is what the code declares: the output of
#   saccade demo --list-components --markdown
#   cmake -DSACCADE=<saccade binary> -DROOT=<repository> -P tests/docs/check_components.cmake
# Fails with the command that brings the page up to date.
cmake_minimum_required(VERSION 3.25)
if(NOT SACCADE OR NOT ROOT)
  message(FATAL_ERROR "usage: cmake -DSACCADE=<saccade> -DROOT=<repository> -P check_components.cmake")
endif()
execute_process(COMMAND "${SACCADE}" demo --list-components --markdown
                OUTPUT_VARIABLE _generated RESULT_VARIABLE _rc)
if(NOT _rc EQUAL 0)
  message(FATAL_ERROR "saccade demo --list-components --markdown exited with ${_rc}")
endif()
file(READ "${ROOT}/docs/components.md" _page)
if(NOT _generated STREQUAL _page)
  string(LENGTH "${_generated}" _n1)
  string(LENGTH "${_page}" _n2)
  message(FATAL_ERROR
          "docs/components.md (${_n2} characters) differs from the declarations (${_n1}): run\n"
          "  saccade demo --list-components --markdown > docs/components.md")
endif()
message(STATUS "docs/components.md matches the declarations")
