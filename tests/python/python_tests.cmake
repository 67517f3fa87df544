# The Python package's tests (tests/python/*_test.py): each file is one ctest, run by pytest
# under the interpreter the package was built for (Debian's /usr/bin/python3) with
# PYTHONPATH=build/python. The first line of a file names its tier: `# tier: unit` (no GL) or
# `# tier: gl` (renders). pytest's exit status 5 ("no tests collected") fails the test like
# any other non-zero status: a file whose tests all vanished is an error, not a pass. Nothing
# is written into the source tree (no bytecode, no .pytest_cache).
file(GLOB _python_tests CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/python/*_test.py)
foreach(_file ${_python_tests})
  get_filename_component(_name ${_file} NAME_WE)
  file(STRINGS ${_file} _tier_line LIMIT_COUNT 1 REGEX "^# tier: ")
  string(REGEX REPLACE "^# tier: *([a-z0-9]+).*" "\\1" _tier "${_tier_line}")
  if(NOT _tier MATCHES "^(unit|gl)$")
    message(FATAL_ERROR "${_file}: the first line must be `# tier: unit` or `# tier: gl`")
  endif()
  if(NOT _tier IN_LIST SACCADE_TEST_TIERS)
    continue()
  endif()
  add_test(NAME python.${_name}
           COMMAND ${Python3_EXECUTABLE} -m pytest -q -p no:cacheprovider -rs ${_file}
           WORKING_DIRECTORY ${PROJECT_BINARY_DIR})
  set_tests_properties(python.${_name} PROPERTIES
    LABELS ${_tier} TIMEOUT 600
    ENVIRONMENT "PYTHONPATH=${SACCADE_PYTHON_DIR};PYTHONDONTWRITEBYTECODE=1;SACCADE_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
  # The longest files start first under ctest -j (seconds on CI's 2 cores; see tests/CMakeLists.txt).
  file(STRINGS ${_file} _cost_line LIMIT_COUNT 1 REGEX "^# cost: ")
  if(_cost_line)
    string(REGEX REPLACE "^# cost: *([0-9]+).*" "\\1" _cost "${_cost_line}")
    set_tests_properties(python.${_name} PROPERTIES COST ${_cost})
  endif()
  add_dependencies(tests_${_tier} _saccade)
endforeach()
