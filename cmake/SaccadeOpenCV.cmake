# Finds the OpenCV 4 modules saccade uses from Debian's per-module -dev packages
# (libopencv-core-dev, ...), which ship no OpenCVConfig.cmake, and defines
# saccade::opencv. Only `vision` and the tests link it (DESIGN.md layers).
find_path(SACCADE_OPENCV_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4 REQUIRED)
set(_saccade_opencv_libs)
foreach(_module core imgproc calib3d imgcodecs objdetect video videoio features2d flann)
  find_library(SACCADE_OPENCV_${_module} NAMES opencv_${_module} REQUIRED)
  list(APPEND _saccade_opencv_libs ${SACCADE_OPENCV_${_module}})
endforeach()
add_library(saccade_opencv INTERFACE)
target_include_directories(saccade_opencv SYSTEM INTERFACE ${SACCADE_OPENCV_INCLUDE_DIR})
target_link_libraries(saccade_opencv INTERFACE ${_saccade_opencv_libs})
add_library(saccade::opencv ALIAS saccade_opencv)
