#pragma once
// SensorModel (render/sensor_model.h) with the choice of its exposure kernel (sensor_model.cc),
// for tests: where the CPU has AVX2 it exposes 16 values a step (four groups of 4 lanes),
// elsewhere 1; both give the same bits.

#include "saccade/render/sensor_model.h"

namespace saccade::render {

/// `simd` false: `sensor`'s Expose and ExposeRendered run the portable loop even where the CPU
/// has AVX2 (tests: the two agree to the bit); true (the default): the vector kernel where the
/// CPU has it.
void UseSensorSimd(SensorModel& sensor, bool simd);

}  // namespace saccade::render
