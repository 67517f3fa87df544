#pragma once
// The real robot as pipeline components (issue 7; seed Fig. 2: popeyeRobot and the camera
// acquisition): the same component names and ports as sim.head and sim.cameras, so that a
// hardware file (runtime/pipeline.h) swaps one for the other.
//
// Each component has its header, included here.
#include "saccade/components/hw_cameras.h"
#include "saccade/components/hw_head.h"
