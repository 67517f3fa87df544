#include "saccade/components/demo/fixation_scoring.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "saccade/core/units.h"
#include "saccade/geometry/json.h"
#include "saccade/vision/image_camera.h"

namespace saccade::components::demo {
namespace {

using nlohmann::json;

/// Angle (degrees) between a camera's optical axis and the direction to p_W.
double AxisErrorDeg(const Image& image, const Eigen::Vector3d& p_W) {
  const geometry::Pose X_WC = vision::CameraPoseOf(image);
  const Eigen::Vector3d axis = X_WC.linear().col(2);
  const Eigen::Vector3d to = (p_W - X_WC.translation()).normalized();
  return std::acos(std::clamp(axis.dot(to), -1.0, 1.0)) * kRadToDeg;
}

}  // namespace

json FixationJson(const Fixation& f) {
  json j = {{"target_id", f.target_id},
            {"object", f.object},
            {"is_face", f.is_face},
            {"selected_at_s", f.selected_at},
            {"fixated", f.fixated_at.has_value()},
            {"completed", f.completed}};
  if (f.fixated_at) {
    j["fixated_at_s"] = *f.fixated_at;
    j["time_to_fixate_s"] = *f.fixated_at - f.selected_at;
    j["target_W"] = ToJson<Eigen::Vector3d>(f.p_W);
    j["target_source"] = f.source;
    j["distance_m"] = f.distance_m;
    if (f.has_truth) {
      j["truth_W"] = ToJson<Eigen::Vector3d>(f.truth_W);
      j["error_3d_m"] = f.error_3d_m;
      j["eye_error_deg"] = {{"left", f.left_error_deg}, {"right", f.right_error_deg}};
      if (f.dwell_samples > 0) {
        j["dwell_eye_error_deg"] = {{"samples", f.dwell_samples},
                                    {"left_mean", f.dwell_sum_deg[0] / f.dwell_samples},
                                    {"right_mean", f.dwell_sum_deg[1] / f.dwell_samples},
                                    {"left_max", f.dwell_max_deg[0]},
                                    {"right_max", f.dwell_max_deg[1]}};
      }
    }
  }
  return j;
}

FixationScorer::FixationScorer(const scene::Scene& scene, bool truth)
    : scene_(scene),
      truth_(truth),
      pictures_(truth ? FindPictureFaces(scene) : std::vector<PictureFace>{}) {
  for (const PictureFace& p : pictures_) faces_total_ += p.has_face ? 1 : 0;
}

void FixationScorer::CountDecoyRejections(int64_t step, const Latest& latest) {
  for (const auto& [camera, faces] : latest.faces) {
    if (!faces.image || faces.image->metadata().frame_index != step) continue;
    for (const FacesMessage::Face& face : faces.faces) {
      if (!face.rejected) continue;
      for (const PictureFace& p : pictures_) {
        if (p.has_face) continue;
        const auto box = ProjectedBox(scene_, scene_.objects()[p.object], *faces.image);
        const double cx = face.box.x + face.box.width / 2.0;
        const double cy = face.box.y + face.box.height / 2.0;
        if (box && cx >= (*box)[0] && cx <= (*box)[2] && cy >= (*box)[1] && cy <= (*box)[3]) {
          ++decoy_rejections_[p.name][face.reason];
        }
      }
    }
  }
}

void FixationScorer::Arrive(Fixation& f, double time, const Latest& latest, const Image& left,
                            const Image& right) const {
  f.fixated_at = time;
  f.p_W = latest.target && latest.target->valid ? latest.target->p_W : latest.selection->p_W;
  f.source = latest.target ? latest.target->source : "selection";
  f.distance_m = (f.p_W - 0.5 * (vision::CameraPoseOf(left).translation() +
                                 vision::CameraPoseOf(right).translation()))
                     .norm();
  // Identify the object: the nearest face centre (or decoy picture) to the target.
  double best = 0.35;
  for (const PictureFace& p : pictures_) {
    scene::SceneState state = scene_.InitialState();
    state.time = time;
    const Eigen::Vector3d ref =
        p.has_face ? FaceCentreAt(scene_, p, time)
                   : scene_.ObjectPose(scene_.objects()[p.object], state).translation();
    const double d = (ref - f.p_W).norm();
    if (d < best) {
      best = d;
      f.object = p.name;
      f.is_face = p.has_face;
      f.truth_W = ref;
    }
  }
  if (!truth_) {
    // Real cameras: every target attention picks is a face the detectors found.
    f.object = fmt::format("face {}", f.target_id);
    f.is_face = true;
  }
  f.has_truth = truth_ && f.is_face;
  if (f.has_truth) {
    f.error_3d_m = (f.p_W - f.truth_W).norm();
    f.left_error_deg = AxisErrorDeg(left, f.truth_W);
    f.right_error_deg = AxisErrorDeg(right, f.truth_W);
  }
}

void FixationScorer::AddDwellSample(Fixation& f, double time, const Image& left,
                                    const Image& right) const {
  // Pursuit: how well the eyes stay on the (possibly moving) true face centre.
  const PictureFace* p = nullptr;
  for (const PictureFace& q : pictures_) {
    if (q.name == f.object) p = &q;
  }
  const Eigen::Vector3d truth = FaceCentreAt(scene_, *p, time);
  const double e[2] = {AxisErrorDeg(left, truth), AxisErrorDeg(right, truth)};
  for (int k = 0; k < 2; ++k) {
    f.dwell_sum_deg[k] += e[k];
    f.dwell_max_deg[k] = std::max(f.dwell_max_deg[k], e[k]);
  }
  ++f.dwell_samples;
}

FixationScorer::Step FixationScorer::Update(int64_t step, double time, const Latest& latest) {
  CountDecoyRejections(step, latest);

  Step out;
  out.status = "looking for faces";
  const SelectionMessage* sel = latest.selection ? &*latest.selection : nullptr;
  if (sel == nullptr) return out;

  if (sel->valid && !sel->exploring) {
    if (fixations_.empty() || fixations_.back().target_id != sel->target_id) {
      Fixation f;
      f.target_id = sel->target_id;
      f.selected_at = time;
      fixations_.push_back(f);
    }
    Fixation& f = fixations_.back();
    out.status = fmt::format("target {}: {}", f.target_id, sel->fixating ? "fixating" : "saccade");
    const auto left = latest.images.find("left");
    const auto right = latest.images.find("right");
    if (sel->fixating && left != latest.images.end() && right != latest.images.end()) {
      if (!f.fixated_at) {
        Arrive(f, time, latest, *left->second, *right->second);
        out.fixated_now = true;
      }
      if (f.has_truth) AddDwellSample(f, time, *left->second, *right->second);
    }
  } else if (sel->exploring) {
    out.status = "exploring: looking straight ahead";
  }
  // A fixated target is complete once inhibition of return suppresses it, whether the
  // selection is still on it or has moved away.
  for (Fixation& f : fixations_) {
    if (!f.fixated_at || f.completed) continue;
    for (const Eigen::Vector3d& s : sel->suppressed_W) {
      if ((s - f.p_W).norm() < 0.2) f.completed = true;
    }
  }
  return out;
}

int FixationScorer::faces_fixated() const {
  int n = 0;
  std::vector<std::string> seen;
  for (const Fixation& f : fixations_) {
    if (f.fixated_at && f.is_face && std::find(seen.begin(), seen.end(), f.object) == seen.end()) {
      seen.push_back(f.object);
      ++n;
    }
  }
  return n;
}

int FixationScorer::faces_done() const {
  int done = 0;
  for (const PictureFace& p : pictures_) {
    if (!p.has_face) continue;
    for (const Fixation& f : fixations_) {
      if (f.object == p.name && f.completed) {
        ++done;
        break;
      }
    }
  }
  return done;
}

json FixationScorer::DecoysJson() const {
  json decoys = json::array();
  for (const PictureFace& p : pictures_) {
    if (p.has_face) continue;
    bool fixated = false;
    for (const Fixation& f : fixations_) fixated = fixated || (f.fixated_at && f.object == p.name);
    int rejected = 0;
    const auto it = decoy_rejections_.find(p.name);
    const std::map<std::string, int> by_reason =
        it == decoy_rejections_.end() ? std::map<std::string, int>{} : it->second;
    for (const auto& [reason, n] : by_reason) rejected += n;
    decoys.push_back({{"name", p.name},
                      {"fixated", fixated},
                      {"rejected", !fixated},
                      {"rejected_detections", rejected},
                      {"by_reason", by_reason}});
  }
  return decoys;
}

}  // namespace saccade::components::demo
