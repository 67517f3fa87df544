#pragma once
// SensorModel (render/sensor_model.h) with the choice of its exposure kernel (sensor_model.cc),
// for tests: where the CPU has AVX-512 it exposes 16 values a step (two groups of 8 lanes),
// where it has AVX2 16 (four groups of 4 lanes), elsewhere 1; all give the same bits.

#include "saccade/render/sensor_model.h"

namespace saccade::render {

/// `sensor`'s Expose and ExposeRendered run the widest kernel of at most `max_lanes` lanes that
/// the CPU has: 8 (AVX-512, the default), 4 (AVX2), 1 (the portable loop). Tests: all agree to
/// the bit.
void UseSensorLanes(SensorModel& sensor, int max_lanes);

}  // namespace saccade::render
