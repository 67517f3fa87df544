// fk, ik, camera: the kinematics and camera-model subcommands.

#include <fmt/format.h>

#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "saccade/core/error.h"
#include "saccade/geometry/calibration_report.h"
#include "saccade/head/fixation.h"
#include "saccade/head/head_description.h"
#include "saccade/head/head_model.h"
#include "saccade/head/kinematics.h"
#include "saccade/head/report.h"

namespace saccade::app {
namespace {

int RunFk(const std::string& head_path, const std::vector<double>& joint_values, bool degrees,
          bool as_json) {
  const head::HeadModel model = head::HeadModel::FromFile(head_path);
  const head::JointState q = JointsFromArgs(model, joint_values, degrees);
  // POPEYE's legacy file: appendix A's chain and report, as always.
  if (const std::optional<head::HeadDescription> head = model.AppendixAHead()) {
    const head::PopeyeJoints p{q[0], q[1], q[2], q[3]};
    if (as_json) {
      std::cout << head::FkReportJson(*head, p).dump(2) << "\n";
    } else {
      fmt::print("{}", head::FkReportText(*head, p));
    }
    return 0;
  }
  if (as_json) {
    std::cout << head::FkReportJson(model, q).dump(2) << "\n";
  } else {
    fmt::print("{}", head::FkReportText(model, q));
  }
  return 0;
}

int RunIk(const std::string& head_path, const std::vector<double>& target, const std::string& mode,
          bool as_json) {
  const head::HeadModel model = head::HeadModel::FromFile(head_path);
  const Eigen::Vector3d p_W(target[0], target[1], target[2]);
  if (const std::optional<head::HeadDescription> head = model.AppendixAHead()) {
    head::IkOptions options;
    options.mode =
        mode == "independent" ? head::VergenceMode::kIndependent : head::VergenceMode::kSymmetric;
    const head::IkResult result = head::SolveFixation(*head, p_W, options);
    if (as_json) {
      std::cout << head::IkReportJson(*head, p_W, mode, result).dump(2) << "\n";
    } else {
      fmt::print("{}", head::IkReportText(p_W, result));
    }
    return 0;
  }
  if (mode != "symmetric") {
    throw InvalidArgument("ik: --mode applies to POPEYE's legacy head file; " + head_path +
                          " fixates by its own rule (its `fixation:` block)");
  }
  const head::FixationResult result = head::SolveFixation(model, p_W);
  if (as_json) {
    std::cout << head::IkReportJson(model, p_W, result).dump(2) << "\n";
  } else {
    fmt::print("{}", head::IkReportText(model, p_W, result));
  }
  return 0;
}

int RunCamera(const geometry::CalibrationReportInput& input, bool as_json) {
  // A file without an image size (stereo_calib's intrinsics.yml): the user gives it.
  if (!input.size && !geometry::ReadCalibrationImageSize(input.path)) {
    throw InvalidArgument(input.path.string() +
                          ": the file stores no image size (image_width, image_height); give "
                          "it with --size W H (OpenCV's stereo_calib sample images are 640 x 480)");
  }
  if (as_json) {
    std::cout << geometry::CalibrationReportJson(input).dump(2) << "\n";
  } else {
    fmt::print("{}", geometry::CalibrationReportText(input));
  }
  return 0;
}

}  // namespace

Runner AddFkCommand(CLI::App& app) {
  struct Options {
    std::string head = ShippedFile("robots/popeye.yaml");
    std::vector<double> joints;
    bool degrees = false, json = false;
  };
  auto o = std::make_shared<Options>();
  auto* fk = app.add_subcommand("fk",
                                "Forward kinematics: camera poses and fixation point for "
                                "joint values (any head; POPEYE's: seed appendix A, eqs. 4-9).");
  fk->add_option("--head", o->head,
                 "Head file (robots/*.yaml: a URDF and what it lacks, or POPEYE's legacy file)")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
  fk->add_option("--joints", o->joints,
                 "One value per actuated joint, in the head's order (POPEYE: PAN TILT LEFT "
                 "RIGHT); radians (m for prismatic joints), or degrees with --deg")
      ->expected(1, 64)
      ->required();
  fk->add_flag("--deg", o->degrees, "Joint angles are in degrees");
  fk->add_flag("--json", o->json, "Print JSON (stable interface, docs/cli.md)");
  return [o] { return RunFk(o->head, o->joints, o->degrees, o->json); };
}

Runner AddIkCommand(CLI::App& app) {
  struct Options {
    std::string head = ShippedFile("robots/popeye.yaml");
    std::vector<double> target;
    std::string mode = "symmetric";
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  auto* ik = app.add_subcommand("ik",
                                "Inverse kinematics: joint angles that fixate a 3D point "
                                "with both optical axes (any head by its fixation rule; "
                                "POPEYE's legacy file: eqs. 10-13).");
  ik->add_option("--head", o->head,
                 "Head file (robots/*.yaml: a URDF and what it lacks, or POPEYE's legacy file)")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
  ik->add_option("--target", o->target, "X Y Z of the point to fixate, in metres, world frame")
      ->expected(3)
      ->required();
  ik->add_option("--mode", o->mode,
                 "POPEYE's legacy file only: symmetric (left = -right) or independent (pan held "
                 "at 0); other heads follow their file's fixation rule")
      ->check(CLI::IsMember({"symmetric", "independent"}))
      ->capture_default_str();
  ik->add_flag("--json", o->json, "Print JSON (stable interface, docs/cli.md)");
  return [o] { return RunIk(o->head, o->target, o->mode, o->json); };
}

Runner AddCameraCommand(CLI::App& app) {
  struct Options {
    std::string calibration, right, extrinsics;
    std::vector<int> size;
    double near = 0.01, far = 100.0;
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  auto* camera = app.add_subcommand(
      "camera",
      "Describe a calibration file: intrinsics, distortion, field of view, OpenGL projection; "
      "for a stereo pair (OpenCV's M1 D1 M2 D2 [R T], or a ROS left/right pair) both cameras, "
      "R and T, the baseline and the rectification.");
  camera
      ->add_option("--calibration", o->calibration,
                   "OpenCV YAML/XML or ROS camera_info YAML calibration file: one camera, or a "
                   "stereo pair in OpenCV's form (M1 D1 M2 D2, R T), or a ROS pair's left camera "
                   "with --right")
      ->check(CLI::ExistingFile)
      ->required();
  camera
      ->add_option("--right", o->right,
                   "The right camera_info of a ROS stereo pair (--calibration is the left): R "
                   "and T from their rectification and projection matrices")
      ->check(CLI::ExistingFile);
  camera
      ->add_option("--extrinsics", o->extrinsics,
                   "R and T of an OpenCV stereo file that stores none (stereo_calib's "
                   "extrinsics.yml beside intrinsics.yml)")
      ->check(CLI::ExistingFile);
  camera
      ->add_option("--size", o->size,
                   "W H: the image size in pixels, for files that store none (image_width, "
                   "image_height)")
      ->expected(2)
      ->check(CLI::Range(1, 100000));
  camera->add_option("--near", o->near, "Near clip plane of the OpenGL projection (m)")
      ->capture_default_str();
  camera->add_option("--far", o->far, "Far clip plane of the OpenGL projection (m)")
      ->capture_default_str();
  camera->add_flag("--json", o->json, "Print JSON (stable interface, docs/cli.md)");
  return [o] {
    geometry::CalibrationReportInput input;
    input.path = o->calibration;
    if (!o->right.empty()) input.right = o->right;
    if (!o->extrinsics.empty()) input.extrinsics = o->extrinsics;
    if (o->size.size() == 2) input.size = geometry::ImageSize{o->size[0], o->size[1]};
    input.near = o->near;
    input.far = o->far;
    return RunCamera(input, o->json);
  };
}

}  // namespace saccade::app
