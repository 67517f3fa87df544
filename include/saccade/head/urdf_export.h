#pragma once
// A URDF for a head file that has none (issue 42, item 5: `saccade urdf`), for ROS tools
// (robot_state_publisher, RViz, Gazebo). The structure is urdfdom's (urdf::exportURDF of a
// urdf::ModelInterface built from the head's kinematic tree); the numbers are rewritten with
// the shortest text that reads back as the same double (urdfdom prints 6 digits), and links and
// joints keep the tree's order (urdfdom sorts them by name), so the actuated joints, and with
// them saccade's q, come back in the same order.
//
// What the URDF holds:
//   - every link (no visuals, inertia or collisions: a legacy head has none);
//   - every joint: type, origin (xyz, rpy with R = Rz Ry Rx), unit axis, mimic, and for a
//     revolute or prismatic joint <limit lower upper velocity effort="0"> from the head's joint
//     settings (HeadModel::joint: the head file may have narrowed the tree's); a continuous joint
//     gets <limit velocity> only; a mimic joint keeps its tree limits;
//   - per eye, a Gazebo camera: <gazebo reference="LINK"><sensor type="camera"
//     name="left_camera"> (right_camera), LINK the eye camera's link, <pose> Gazebo's camera
//     frame (x forward, z up) in that link = the optical frame turned back by
//     rpy(-pi/2, 0, -pi/2) (urdf.h), <horizontal_fov> = 2 atan(width / 2 / fx), <image> width
//     and height, <clip> near/far (the camera's, else 0.02 / 50 m), <distortion> k1 k2 k3 p1 p2
//     <center>0.5 0.5 for a radial-tangential model.
// What it cannot hold: the head's pose in the world (a head file's `pose:`), accelerations,
// servos and the fixation rule (a head file gives them beside the URDF: robots/humanoid.yaml).
//
// Gazebo's camera is a square-pixel pinhole with the principal point at the image centre and at
// most 5 radial-tangential coefficients. A camera that is not one (fx != fy, principal point off
// ((width - 1) / 2, (height - 1) / 2), skew, fisheye, k4..k6 != 0) is still written with the
// nearest values (fx for the field of view, the centre, no skew, no fisheye distortion, the
// first five coefficients) and an XML comment in its <sensor> saying what differs; the result's
// warnings say the same.

#include <string>
#include <vector>

#include "saccade/head/head_model.h"

namespace saccade::head {

/// The text of a URDF and what it could not express exactly.
struct UrdfExport {
  std::string xml;                    ///< the URDF document
  std::vector<std::string> warnings;  ///< one line per camera property Gazebo cannot express
};

/// The head's URDF. For a head loaded from a URDF (urdf_xml() not empty) that text, unchanged,
/// without warnings; otherwise the document this file's header describes. Never throws on a
/// valid HeadModel.
UrdfExport ExportUrdf(const HeadModel& head);

}  // namespace saccade::head
