#pragma once
// Cyclone DDS's C API and the types idlc generates from src/dds/idl/ros2_messages.idl: private
// to the dds module (as OpenGL is to render).
#include <dds/dds.h>

#include <string>

#include "ros2_messages.h"  // generated in the build folder by idlc -t
#include "saccade/core/error.h"

namespace saccade::dds::internal {

/// Throws saccade::Error "what: Cyclone's reason" when `rc` is a Cyclone error code (< 0).
inline int32_t Check(int32_t rc, const std::string& what) {
  if (rc < 0) throw Error(what + ": " + dds_strretcode(rc));
  return rc;
}

}  // namespace saccade::dds::internal
