#pragma once
// Perception as pipeline components (seed Fig. 2, middle block; section 5.2: featuresHaar,
// camshiftTracking, triangulation). Each wraps a class of `vision` and documents its ports;
// each declares its parameters in its constructor (docs/components.md is printed from them).
//
// vision.undistort / vision.median / vision.sharpen -- pre-processing (seed Fig. 2).
//   inputs: image (runtime.image, required); outputs: image (runtime.image), a new image with
//   the same metadata (undistort: distortion "none").
//
// vision.face_detector -- Haar faces with the cat and eye checks (vision/face_detector.h).
//   inputs: image (runtime.image, required); outputs: faces (vision.faces), every new image.
//
// vision.stereo_faces -- associates the left and right faces and triangulates them (seed 4.2).
//   inputs: left, right (vision.faces, required); outputs: candidates (vision.candidates)
//
// vision.attention -- chooses the face to look at: the closest one that inhibition of return
//   (seed 7.2) does not suppress; sticks to it until it has been fixated for fixation_time_s
//   (then it is suppressed for suppression_time_s) or unseen for lost_after_s. With nothing to
//   look at for explore_after_s, it sends the head home (a point home_distance_m straight
//   ahead of its base), from where it looks for faces again.
//   inputs: candidates (vision.candidates, required), joints (head.joints, delay 1)
//   outputs: selection (vision.selection)
//   methods: reset (runtime.empty -> runtime.text): forgets the target and every suppressed
//            place, so that every face is new again.
//
// vision.camshift -- one eye's CamShift track of the selected face (vision/camshift_tracker.h),
//   seeded by its detection box, re-seeded when a detection of the same target lies farther
//   than reseed_fraction of its width from the track, re-detected when lost.
//   inputs: image (runtime.image, required), selection (vision.selection, required)
//   outputs: track (vision.track)
//
// vision.triangulate -- the 3D target: the selection's point (triangulated detections) when
//   this frame's detections found the target, else the two eyes' CamShift tracks triangulated
//   (they bridge the frames the detector misses: motion blur, perspective), else the
//   selection's last point. `prefer: tracks` uses the tracks even when detections exist:
//   measured on the portraits, CamShift's window slides down onto the neck's skin, 22 mm
//   off the face centre at 2.2 m against 4 mm for the detections.
//   inputs: left, right (vision.track, required), selection (vision.selection, required)
//   outputs: target (vision.target)
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
