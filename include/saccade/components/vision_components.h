#pragma once
// Perception as pipeline components (seed Fig. 2, middle block; section 5.2: featuresHaar,
// camshiftTracking, triangulation), each wrapping a class of `vision`:
//
// - vision.undistort, vision.median, vision.sharpen: pre-processing (seed Fig. 2);
// - vision.face_detector: Haar faces with the cat and eye checks (vision/face_detector.h);
// - vision.stereo_faces: associates the two eyes' faces and triangulates them (seed 4.2);
// - vision.attention: chooses the face to look at, with inhibition of return (seed 7.2);
// - vision.camshift: one eye's CamShift track of the selected face;
// - vision.triangulate: the 3D target the fixation controller is given.
//
// Their ports, methods and parameters are declared once, in each component's constructor, and
// docs/components.md is printed from those declarations (`saccade demo --list-components
// --markdown`); each component's header says how it behaves.
//
// Each component has its header, included here.
#include "saccade/components/attention_component.h"
#include "saccade/components/camshift_component.h"
#include "saccade/components/face_detector_component.h"
#include "saccade/components/image_filter_component.h"
#include "saccade/components/median_component.h"
#include "saccade/components/sharpen_component.h"
#include "saccade/components/stereo_faces_component.h"
#include "saccade/components/triangulate_component.h"
#include "saccade/components/undistort_component.h"
