# Installs saccade into a temporary prefix, builds tests/install/consumer against it with
# find_package(saccade), runs it on an installed scene, and checks what it printed.
#   cmake -DBUILD=<saccade build dir> -DSOURCE=<repository> -DWORK=<scratch dir>
#         -P tests/install/check_install.cmake
cmake_minimum_required(VERSION 3.25)
foreach(_v BUILD SOURCE WORK)
  if(NOT ${_v})
    message(FATAL_ERROR "usage: cmake -DBUILD=... -DSOURCE=... -DWORK=... -P check_install.cmake")
  endif()
endforeach()
file(REMOVE_RECURSE "${WORK}")
set(_prefix "${WORK}/prefix")

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE _rc OUTPUT_VARIABLE _out ERROR_VARIABLE _err)
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${_rc}):\n${_out}\n${_err}")
  endif()
  set(OUT "${_out}" PARENT_SCOPE)
endfunction()

run("cmake --install" ${CMAKE_COMMAND} --install "${BUILD}" --prefix "${_prefix}")
foreach(_f include/saccade/head/kinematics.h lib/libsaccade_core.a bin/saccade
           lib/cmake/saccade/saccadeConfig.cmake share/saccade/robots/popeye.yaml
           share/saccade/scenes/bench.yaml share/saccade/web/public/index.html)
  if(NOT EXISTS "${_prefix}/${_f}")
    message(FATAL_ERROR "not installed: ${_f}")
  endif()
endforeach()
# No private dependency's header is reachable from the public headers: none includes GL, EGL,
# Boost, spdlog, Assimp or yaml-cpp.
file(GLOB_RECURSE _headers "${_prefix}/include/saccade/*.h")
foreach(_h IN LISTS _headers)
  file(STRINGS "${_h}" _bad REGEX "#include [<\"](GL|EGL|epoxy|boost|spdlog|assimp|yaml-cpp)/")
  if(_bad)
    message(FATAL_ERROR "${_h} includes a private dependency: ${_bad}")
  endif()
endforeach()

run("configuring the consumer" ${CMAKE_COMMAND} -S "${SOURCE}/tests/install/consumer"
    -B "${WORK}/consumer" -G Ninja -DCMAKE_PREFIX_PATH=${_prefix} -DCMAKE_BUILD_TYPE=Release)
run("building the consumer" ${CMAKE_COMMAND} --build "${WORK}/consumer")
run("running the consumer" "${WORK}/consumer/consumer" "${_prefix}/share/saccade/scenes/bench.yaml")
message(STATUS "${OUT}")
if(NOT OUT MATCHES "left camera at [-0-9.]+ [-0-9.]+ [-0-9.]+, image [0-9]+x[0-9]+")
  message(FATAL_ERROR "unexpected output: ${OUT}")
endif()
file(REMOVE_RECURSE "${WORK}")  # half a gigabyte of static libraries with debug information
