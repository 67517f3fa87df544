#pragma once
// The readers that both head file formats share (head_description.cc: the legacy POPEYE file;
// head_model.cc: the file that names a URDF): angles in `_deg` or radians, servo blocks, the
// pose of the head, a camera's intrinsics. Each throws FileError naming file, line and key.
#include <optional>
#include <string>

#include "core/internal_yaml.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/pose.h"
#include "saccade/head/head_description.h"

namespace saccade::head::internal {

using saccade::internal::Entry;

/// An angle given either as `<key>_deg` (degrees) or `<key>` (radians): exactly one of them;
/// std::nullopt when neither. `degrees` tells which.
std::optional<Entry> FindAngleEntry(const Entry& parent, const std::string& key, bool* degrees);
/// Same, required.
Entry GetAngleEntry(const Entry& parent, const std::string& key, bool* degrees);
/// An angle key's value in radians, when present.
std::optional<double> FindAngle(const Entry& parent, const std::string& key);

/// A `servo:` block (head_description.h, ServoMapping).
ServoMapping ReadServo(const Entry& e);
/// A `pose:` block: position and rpy (R = Rz Ry Rx).
geometry::Pose ReadPose(const Entry& e);
/// A camera's intrinsics block; `extra_keys` are other keys the caller reads from the same map.
geometry::CameraModel ReadCamera(const Entry& e, const std::vector<std::string>& extra_keys = {});

}  // namespace saccade::head::internal
