#pragma once
// Scoring the active-vision loop against the scene's ground truth (face_truth.h): which
// object each fixation landed on, how far the triangulated target was from the true face
// centre, how far each eye's optical axis points from it (at arrival and over the dwell,
// while pursuing), which decoys (the cat) were rejected and why. `saccade demo` reports it;
// the closed-loop tests assert on it. With real cameras there is no ground truth: every
// target attention picks counts as a face, reported as triangulated.
#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "saccade/components/demo/face_truth.h"
#include "saccade/components/demo/loop_outputs.h"
#include "saccade/scene/scene.h"

namespace saccade::components::demo {

/// One target attention selected, and how the head fixated it.
struct Fixation {
  int64_t target_id = -1;
  double selected_at = 0.0;
  std::optional<double> fixated_at;
  bool completed = false;  // inhibition of return suppressed it
  std::string object = "unknown";
  bool is_face = false;
  bool has_truth = false;  // the simulated scene gave the true face centre
  std::string source;
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d truth_W = Eigen::Vector3d::Zero();
  double distance_m = 0.0;
  double error_3d_m = 0.0;
  double left_error_deg = 0.0;
  double right_error_deg = 0.0;
  // Over the dwell (pursuit of a moving face): per-eye angular error, mean and max.
  int dwell_samples = 0;
  double dwell_sum_deg[2] = {0.0, 0.0};
  double dwell_max_deg[2] = {0.0, 0.0};
};

/// Its JSON form in the demo's report (docs/demo.md).
nlohmann::json FixationJson(const Fixation& f);

class FixationScorer {
 public:
  /// `truth`: the cameras are rendered from `scene`, whose pictures are what they see.
  FixationScorer(const scene::Scene& scene, bool truth);

  struct Step {
    std::string status;        ///< "target 2: saccade", "looking for faces", ...
    bool fixated_now = false;  ///< the newest fixation arrived in this step
  };
  /// After each step, with what the loop said in it.
  Step Update(int64_t step, double time, const Latest& latest);

  const std::vector<Fixation>& fixations() const { return fixations_; }
  /// Faces in the scene's pictures (0 without ground truth).
  int faces_total() const { return faces_total_; }
  /// Different faces fixated.
  int faces_fixated() const;
  /// Faces fixated and then let go (suppressed): the demo ends when all are.
  int faces_done() const;
  /// [{name, fixated, rejected, rejected_detections, by_reason}] per decoy picture.
  nlohmann::json DecoysJson() const;

 private:
  /// Rejected detections on a decoy picture (the cat) in this step's images, by reason.
  void CountDecoyRejections(int64_t step, const Latest& latest);
  /// The fixation arrives: its target, distance and object, and its errors against the truth.
  void Arrive(Fixation& f, double time, const Latest& latest, const Image& left,
              const Image& right) const;
  /// One step of the dwell: each eye's angular error from the true face centre.
  void AddDwellSample(Fixation& f, double time, const Image& left, const Image& right) const;

  const scene::Scene& scene_;
  bool truth_;
  std::vector<PictureFace> pictures_;
  int faces_total_ = 0;
  std::vector<Fixation> fixations_;
  std::map<std::string, std::map<std::string, int>> decoy_rejections_;  // picture, reason
};

}  // namespace saccade::components::demo
