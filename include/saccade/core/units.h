#pragma once
// Degrees and radians: one definition for every module (files show degrees, code works in
// radians).
#include <numbers>

namespace saccade {

inline constexpr double kDegToRad = std::numbers::pi / 180.0;
inline constexpr double kRadToDeg = 180.0 / std::numbers::pi;

}  // namespace saccade
