// The robot's body from primitives (internal_robot_body.h). Sizes follow the half baseline B;
// the layout keeps every part behind the eye cameras' optical centres, so no joint angle within
// reach lets an eye camera look into its own eye or through the head plate.

#include "internal_robot_body.h"

#include <algorithm>

#include "saccade/core/error.h"

namespace saccade::scene::internal {
namespace {

geometry::Pose At(double x, double y, double z) {
  geometry::Pose X = geometry::Pose::Identity();
  X.translation() = Eigen::Vector3d(x, y, z);
  return X;
}

}  // namespace

std::vector<RobotPart> BuildRobotBody(const head::HeadModel& head) {
  SACCADE_ASSERT(head.appendix_a().has_value(), "BuildRobotBody: not a legacy POPEYE head");
  const head::HeadGeometry& g = *head.appendix_a();
  const head::KinematicTree& tree = head.tree();
  enum Link { kBase, kNeck, kCyclopean, kLeftEye, kRightEye };
  const int links[] = {tree.FindLink("base_link"), tree.FindLink("neck_link"),
                       tree.FindLink("cyclopean_link"), tree.FindLink("left_eye_link"),
                       tree.FindLink("right_eye_link")};
  // The paper's axes (x left, y up, z forward) in the links' REP 103 axes.
  Eigen::Matrix3d paper;
  paper << 0, 0, 1,  //
      1, 0, 0,       //
      0, 1, 0;
  const geometry::Pose paper_to_link = geometry::MakePose(paper, Eigen::Vector3d::Zero());
  const double B = g.B;
  const double r = 0.35 * B;       // eyeball radius
  const double margin = 0.02 * B;  // gap between an eye's front and its optical centre

  const auto box_plate = MakeBox({0.20f, 0.22f, 0.25f, 1.0f});
  const auto box_neck = MakeBox({0.35f, 0.35f, 0.38f, 1.0f});
  const auto box_base = MakeBox({0.15f, 0.15f, 0.17f, 1.0f});
  const auto box_pupil = MakeBox({0.03f, 0.03f, 0.03f, 1.0f});
  const auto eyeball = MakeSphere({0.92f, 0.92f, 0.90f, 1.0f}, 32);

  std::vector<RobotPart> parts;
  const auto add = [&](Link link, const geometry::Pose& X,
                       const std::shared_ptr<const Model>& model, const Eigen::Vector3d& size) {
    parts.push_back(RobotPart{links[link], link == kBase ? X : paper_to_link * X, model, size});
  };

  // Eyes: in {l} and {r} the optical centre is at z = delta (eqs. 7-8); everything is behind.
  const std::pair<Link, double> eyes[] = {{kLeftEye, g.delta_l}, {kRightEye, g.delta_r}};
  for (const auto& [link, delta] : eyes) {
    const double front = delta - margin;
    add(link, At(0.0, 0.0, front - r), eyeball, Eigen::Vector3d::Constant(2.0 * r));
    add(link, At(0.0, 0.0, front - 0.05 * r), box_pupil,
        Eigen::Vector3d(0.8 * r, 0.8 * r, 0.1 * r));
  }

  // Head plate in {c}, behind the eyeballs however the eyes turn: an eyeball's centre stays
  // within (margin + r) - min(delta, 0) of its rotation axis.
  const double plate_front = std::min({g.delta_l, g.delta_r, 0.0}) - 2.0 * r - 2.0 * margin;
  const double plate_depth = 0.4 * B;
  const double plate_z = plate_front - 0.5 * plate_depth;
  const double plate_height = 2.4 * r;
  add(kCyclopean, At(0.0, 0.0, plate_z), box_plate,
      Eigen::Vector3d(2.0 * B + 2.0 * r + 0.3 * B, plate_height, plate_depth));

  // Neck column in the neck frame (after pan, before tilt), under the plate.
  const double top = std::min(g.D, g.D + g.H) - 0.5 * plate_height;
  const double bottom = std::min(-1.4 * B, top - 0.2 * B);
  add(kNeck, At(0.0, 0.5 * (top + bottom), plate_z), box_neck,
      Eigen::Vector3d(0.5 * B, top - bottom, 0.5 * B));

  // Pedestal in the base frame B (x forward, y left, z up): the paper's z is B's x, y is z.
  const double pedestal_height = 0.3 * B;
  add(kBase, At(plate_z, 0.0, bottom - 0.5 * pedestal_height), box_base,
      Eigen::Vector3d(1.6 * B, 1.6 * B, pedestal_height));
  return parts;
}

std::vector<RobotPart> BuildUrdfVisuals(const head::HeadModel& head, AssetCache& cache) {
  std::vector<RobotPart> parts;
  const Eigen::Vector4f grey(0.6f, 0.6f, 0.62f, 1.0f);
  for (const head::UrdfVisual& visual : head.visuals()) {
    const Eigen::Vector4f color = visual.rgba ? visual.rgba->cast<float>() : grey;
    RobotPart part{visual.link, visual.X_LV, nullptr, Eigen::Vector3d::Ones()};
    switch (visual.shape) {
      case head::UrdfVisual::Shape::kBox:
        part.model = MakeBox(color);
        part.scale = visual.size;
        break;
      case head::UrdfVisual::Shape::kSphere:
        part.model = MakeSphere(color);
        part.scale = Eigen::Vector3d::Constant(2.0 * visual.size.x());
        break;
      case head::UrdfVisual::Shape::kCylinder:
        part.model = MakeCylinder(color);
        part.scale = Eigen::Vector3d(2.0 * visual.size.x(), 2.0 * visual.size.y(), visual.size.z());
        break;
      case head::UrdfVisual::Shape::kMesh: {
        std::shared_ptr<const Model> model =
            LoadModelFile(std::filesystem::canonical(visual.mesh_path), nullptr, cache);
        if (visual.rgba) {
          auto tinted = std::make_shared<Model>(*model);
          for (Material& m : tinted->materials) {
            m.base_color = color;
            m.texture = nullptr;
          }
          model = tinted;
        }
        part.model = model;
        part.scale = visual.scale;
        break;
      }
    }
    parts.push_back(std::move(part));
  }
  return parts;
}

}  // namespace saccade::scene::internal
