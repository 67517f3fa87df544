#pragma once
// The simulated robot as pipeline components (seed Fig. 2, left block): the cameras rendered
// from a scene, and the head's motors. The real robot replaces them by components with the
// same ports (issue 7).
//
// Each declares its parameters in its constructor (docs/components.md is printed from them).
//
// sim.cameras -- renders the scene's cameras (seed: cameraCapture through the FBO), one image
//   output per camera of its `cameras` parameter.
//   inputs:  joints (head.joints, optional): the head's state at this step's time; connect
//            it from sim.head with delay 1. Without it, the scene's initial joints.
//   outputs: <camera> (runtime.image) per camera, shared; frame index = step.
//
// sim.head -- the head's four motors under their velocity and acceleration limits
//   (head/motors.h): saccades and smooth pursuit, never outside the joint limits.
//   Its scene's robot is the head (description, initial joints).
//   inputs:  command (head.command, optional): the latest command, applied when it arrives
//   outputs: joints (head.joints): the state at the end of the step (time + dt), i.e. at the
//            next step's time, which is when the cameras see it. The motors advance by the
//            time since the last state: dt in simulated time, the wall time in real time.
//   methods: state (runtime.empty -> head.joints): the joints now;
//            move (head.command -> head.joints): a command, as on the input, clamped to the
//              limits (the reply's targets say where it goes); NaN or infinite values fail;
//            stop (runtime.empty -> head.joints): brakes every joint and holds where it stops.
//
// Each component has its header, included here.
#include "saccade/components/debug_fault.h"
#include "saccade/components/sim_cameras.h"
#include "saccade/components/sim_head.h"
