# Renames the C symbols idlc generated from tests/dds/idl/ros2_reference.idl (ref_...), so that
# the tests' own ROS 2 types link beside saccade's (the type names on the wire stay the same).
# cmake -DFILES="a.c;a.h" -P rename_symbols.cmake
foreach(_file ${FILES})
  file(READ ${_file} _text)
  foreach(_pkg builtin_interfaces std_msgs sensor_msgs geometry_msgs tf2_msgs rosgraph_msgs)
    string(REPLACE "${_pkg}_msg_dds__" "ref_${_pkg}_msg_dds__" _text "${_text}")
  endforeach()
  file(WRITE ${_file} "${_text}")
endforeach()
