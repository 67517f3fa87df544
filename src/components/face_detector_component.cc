#include "saccade/components/face_detector_component.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <tuple>
#include <utility>
#include <vector>

#include "components/internal_frames.h"
#include "components/internal_scene.h"
#include "saccade/core/error.h"
#include "saccade/head/kinematics.h"
#include "saccade/vision/image_camera.h"

namespace saccade::components {

using internal::Centre;
using internal::FrameOf;

namespace {

using Options = vision::FaceDetector::Options;

// Two boxes of one face: they overlap by more than half the smaller one.
bool SameFace(const cv::Rect& a, const cv::Rect& b) {
  return (a & b).area() > 0.5 * std::min(a.area(), b.area());
}

// The overlap (of the union) at which a face found around one the discovery lane found takes
// its verdict: a box of the same size, moved by half its side.
constexpr double kRevisitVerdictOverlap = 1.0 / 3.0;

// A search on a thread of its own is taken at its due step on the simulated clock (exactly,
// so that runs repeat; get() then waits for as long as it takes), in real time once done.
template <typename T>
bool Due(const std::future<T>& search, const runtime::StepContext& context, int64_t due_step) {
  if (!search.valid()) return false;
  return context.realtime ? search.wait_for(std::chrono::seconds(0)) == std::future_status::ready
                          : context.step >= due_step;
}

// A box `scale` times `size` centred on (cx, cy), clipped to `image`.
cv::Rect BoxAround(double cx, double cy, const cv::Size& size, double scale, const Image& image) {
  // A point the head fixates projects onto the principal point, often (width - 1) / 2 exactly
  // in one process and within 1e-13 px of it in another (the poses cross DDS as quaternions):
  // rounded at exactly an integer, those would give boxes a pixel apart and the runs would part.
  // Values within kSnapPx of an integer count as that integer.
  constexpr double kSnapPx = 1e-6;
  const double w = scale * size.width;
  const double h = scale * size.height;
  return cv::Rect(static_cast<int>(std::floor(cx - 0.5 * w + kSnapPx)),
                  static_cast<int>(std::floor(cy - 0.5 * h + kSnapPx)),
                  static_cast<int>(std::ceil(w - kSnapPx)),
                  static_cast<int>(std::ceil(h - kSnapPx))) &
         cv::Rect(0, 0, image.width(), image.height());
}

}  // namespace

FaceDetectorComponent::FaceDetectorComponent()
    : image_(AddInput<runtime::ImageMessage>("image", /*required=*/true)),
      track_(AddInput<TrackMessage>("track")),
      selection_(AddInput<SelectionMessage>("selection")),
      partner_(AddInput<FacesMessage>("partner")),
      faces_(AddOutput<FacesMessage>("faces")) {
  // In the order the component reference lists them.
  DeclareImageParams();
  DeclareTrackParams();
  DeclareCascadeParams();
}

void FaceDetectorComponent::DeclareImageParams() {
  DeclareParam("cascade", &cascade_,
               "the face cascade: haar (alt2) or lbp (frontalface_improved; on "
               "scenes/portraits.yaml it misses the near portrait)")
      .Choices({"haar", "lbp"});
  DeclareParam("pyramid_level", &options_.pyramid_level,
               "search faces on the image halved this many times (a quarter of the pixels a "
               "level); "
               "the cat and eye checks stay on the full image")
      .Range(Options::kPyramidLevels);
  DeclareParam("latency_steps", &latency_steps_,
               "0: detect within the step; N: detect on a thread of its own, the faces emitted N "
               "steps after their image (simulated clock; real time: once ready)")
      .Range(0, 100);
  DeclareParam("discovery_latency_steps", &discovery_latency_steps_,
               "with a track input and latency_steps 0: 0: the whole-image searches for the "
               "other faces run within the step; D: on a thread of their own, the faces they "
               "find searched again D steps later around where they were, in that step's image "
               "(simulated clock: exactly D; real time: once done), so that they never hold up "
               "the loop")
      .Range(0, 100);
  DeclareParam("discovery_pyramid_level", &discovery_pyramid_level_,
               "with discovery_latency_steps: the pyramid level of the lane's whole-image "
               "searches (the faces they find are searched again around where they were, at "
               "pyramid_level), and of the whole-image searches for the other faces of a "
               "detector on its own thread in real time (realtime_thread)")
      .Range(Options::kPyramidLevels);
  DeclareParam("realtime_thread", &realtime_thread_,
               "on the real-time clock (saccade demo --realtime, the GUI), detect on a thread of "
               "its own whatever latency_steps says, the faces emitted once ready, so that the "
               "loop runs at camera rate; false: within the step");
}

void FaceDetectorComponent::DeclareTrackParams() {
  DeclareParam("track_region_scale", &track_region_scale_,
               "with a track input: search a box this many times the track's window around "
               "it; 0: always the whole image (so does a detector whose track input is not "
               "connected)")
      .Range(0.0, 100.0);
  DeclareParam("full_scan_every", &full_scan_every_,
               "with a track region: search the whole image every N-th detection (a face that "
               "comes into view is found within N frames)")
      .Range(1, 1000000);
  DeclareParam("new_target_scans", &new_target_scans_,
               "with a track region: on the first N detections of a new target (a saccade's "
               "blur may carry a tracker onto another face) search also around where the "
               "selection input puts it or, without one, the whole image")
      .Range(0, 1000000);
  DeclareParam("region_size_factor", &region_size_factor_,
               "with a track region: search faces from the track window's side / F to its side x "
               "F (within min_size_px, max_size_px); 0: every size")
      .Range(0.0, 100.0);
  DeclareParam("recheck_every", &recheck_every_,
               "with a track input: a face seen again at about the same place (boxes "
               "overlapping by 70 % of their union) keeps its cat and eye verdict for N - 1 "
               "searches, then is checked again; a new target forgets them all (1: check every "
               "face every time)")
      .Range(1, 1000000);
  DeclareParam("keep_target_verdict", &keep_target_verdict_,
               "with a selection input: on a new target's first new_target_scans searches, the "
               "face found where the selection puts it (a third of their union) keeps the "
               "verdict that made it the target (attention chooses only faces both eyes "
               "accepted) instead of running the cat and eye cascades while the head turns to "
               "it; it is checked again like any face (recheck_every, recheck_phase)");
  DeclareParam("recheck_phase", &recheck_phase_,
               "with recheck_every: a face checked for the first time keeps its verdict N "
               "searches fewer before its first check again (the two eyes' detectors at phases "
               "recheck_every / 2 apart check one face on different steps)")
      .Range(0, 1000000);
  DeclareParam("partner_min_depth_m", &partner_min_depth_m_,
               "with a partner input: the nearest depth of a face along its ray from the other "
               "eye (the near end of the band searched)")
      .Range(1e-3, 1e6)
      .Unit("m");
  DeclareParam("partner_max_depth_m", &partner_max_depth_m_,
               "with a partner input: the farthest depth of a face along its ray from the other "
               "eye (the band's far end)")
      .Range(1e-3, 1e6)
      .Unit("m");
}

void FaceDetectorComponent::DeclareCascadeParams() {
  DeclareParam("region_pyramid_level", &region_pyramid_level_,
               "the pyramid level of the search around the track (the whole image's is "
               "pyramid_level)")
      .Range(Options::kPyramidLevels);
  DeclareParam("min_neighbors", &options_.min_neighbors, "overlapping hits needed to keep a box")
      .Range(Options::kNeighbors);
  DeclareParam("scale_factor", &options_.scale_factor, "size step between pyramid levels")
      .Range(Options::kScaleFactors);
  DeclareParam("discovery_scale_factor", &discovery_scale_factor_,
               "with a track region: the size step of the whole-image searches, which look for "
               "the other faces (the tracked face's box comes from the search around it, at "
               "scale_factor); scale_factor's value: one step everywhere")
      .Range(Options::kScaleFactors);
  DeclareParam("min_size_px", &options_.min_size_px, "smallest face side")
      .Range(Options::kMinSizes)
      .Unit("px");
  DeclareParam("max_size_px", &options_.max_size_px,
               "largest face side; 0: no limit, else at least min_size_px")
      .Range(Options::kMaxSizes)
      .Unit("px");
  DeclareParam("reject_cats", &reject_cats_, "reject boxes that the cat-face cascade also finds");
  DeclareParam("require_eyes", &require_eyes_, "reject boxes without an eye inside");
}

vision::FaceDetector::Options FaceDetectorComponent::DetectorOptions() const {
  vision::FaceDetector::Options options = options_;
  options.cascade_path = cascade_ == "lbp" ? vision::kLbpFaceCascade : vision::kHaarFaceCascade;
  if (!reject_cats_) options.cat_cascade_path = "";
  if (!require_eyes_) options.eye_cascade_path = "";
  return options;
}

void FaceDetectorComponent::Configured() {
  // A search on a thread of its own uses the detectors replaced below.
  if (running_.valid()) running_.wait();
  if (discovery_.valid()) discovery_.wait();
  if (!(partner_min_depth_m_ < partner_max_depth_m_)) {
    throw InvalidArgument(
        fmt::format("partner_min_depth_m ({}) must be less than partner_max_depth_m ({})",
                    partner_min_depth_m_, partner_max_depth_m_));
  }
  vision::FaceDetector::Options options = DetectorOptions();
  detector_ = std::make_unique<vision::FaceDetector>(options);
  options.pyramid_level = region_pyramid_level_;
  region_detector_ = std::make_unique<vision::FaceDetector>(options);
  discovery_detector_.reset();
  options = DetectorOptions();
  options.scale_factor = discovery_scale_factor_;
  if (discovery_scale_factor_ != options_.scale_factor) {
    discovery_detector_ = std::make_unique<vision::FaceDetector>(options);
  }
  lane_detector_.reset();
  if (discovery_latency_steps_ > 0 && latency_steps_ == 0) {
    options.pyramid_level = discovery_pyramid_level_;
    lane_detector_ = std::make_unique<vision::FaceDetector>(options);
  }
}

FaceDetectorComponent::Search FaceDetectorComponent::NextSearch(const Image& image) {
  Search search;
  const int64_t n = detections_++;
  if (track_region_scale_ > 0.0 && track_.has_value()) AroundTrack(image, n, &search);
  // A face that one eye alone sees cannot be triangulated: with the other eye's faces of this
  // same capture (the partner input), their epipolar bands instead of the whole image.
  // Not with the discovery lane while tracking: the partner's faces of this capture are then
  // only those around its track.
  if (search.whole && partner_.has_value() && !(lane_detector_ && search.tracked)) {
    std::optional<std::vector<std::pair<cv::Rect, cv::Size>>> bands = PartnerBands(image);
    if (bands) {
      search.whole = false;
      search.bands = std::move(*bands);
    }
  }
  return search;
}

void FaceDetectorComponent::AroundTrack(const Image& image, int64_t n, Search* out) {
  Search& search = *out;
  search.tracked = true;
  const TrackMessage& track = track_.value();
  if (track.target_id != last_target_id_) {
    last_target_id_ = track.target_id;
    whole_scans_left_ = new_target_scans_;
    verdicts_.clear();  // the eyes jump to the new target: what was where may have changed
  }
  for (const Verdict& v : verdicts_) {
    if (v.reuses + 1 < recheck_every_) {
      search.checked.push_back(v.face);
      search.checked_reuses.push_back(v.reuses);
    }
  }
  const bool tracking = track.tracking && track.window.area() > 0;
  if (tracking) {
    search.region =
        BoxAround(track.center.x, track.center.y, track.window.size(), track_region_scale_, image);
    SizesAround(track.window.size(), &search);
  }
  // Without a track, the whole image (searching around where the selection puts a lost target
  // instead left the eyes less steady: bench/baselines/loop-issue14-2core.md); with the
  // discovery lane, the whole image on its thread and around where the selection puts the
  // target at once.
  search.discovery = n % full_scan_every_ == 0;
  search.whole = !tracking || search.discovery;
  if (!tracking && lane_detector_) {
    // No target (attention has none, or looks around): the whole image on the lane. A lost
    // target: around where the selection puts it, now.
    const bool target =
        selection_.has_value() && selection_.value().valid && !selection_.value().exploring;
    cv::Size face;
    search.predicted =
        target ? PredictedRegion(image, track.target_id, &face) : std::optional<cv::Rect>();
    if (search.predicted) SizesAround(face, &search);
    if (!target) search.discovery = true;
    if (search.predicted) search.whole = search.discovery;
  }
  // A new target: around where the selection puts it, or else the whole image.
  if (tracking && whole_scans_left_ > 0) {
    --whole_scans_left_;
    cv::Size face;
    cv::Rect face_box;
    search.predicted = PredictedRegion(image, track.target_id, &face, &face_box);
    if (search.predicted) {
      SizesAround(face, &search);
      if (keep_target_verdict_ && face_box.area() > 0) {
        // Attention chooses only faces that both eyes accepted: the face where the selection
        // puts the target keeps that verdict while the head turns to it (faces move by up to
        // half their side between frames then, hence a third of their union, as revisits).
        vision::FaceDetection target;
        target.box = face_box;
        search.checked.push_back(target);
        search.checked_reuses.push_back(recheck_phase_);  // as if checked for the first time
        search.verdict_overlap = kRevisitVerdictOverlap;
      }
    } else {
      search.whole = true;
    }
  }
}

std::pair<int, int> FaceDetectorComponent::SizeBounds(const cv::Size& face) const {
  if (!(region_size_factor_ > 0.0)) return {0, 0};
  return {static_cast<int>(std::floor(std::min(face.width, face.height) / region_size_factor_)),
          static_cast<int>(std::ceil(std::max(face.width, face.height) * region_size_factor_))};
}

void FaceDetectorComponent::SizesAround(const cv::Size& face, Search* search) const {
  if (!(region_size_factor_ > 0.0)) return;
  const auto [low, high] = SizeBounds(face);
  const bool first = search->max_size_px == 0;  // no bounds yet
  search->min_size_px = first ? low : std::min(search->min_size_px, low);
  search->max_size_px = first ? high : std::max(search->max_size_px, high);
}

std::optional<cv::Rect> FaceDetectorComponent::PredictedRegion(const Image& image,
                                                               int64_t target_id, cv::Size* face,
                                                               cv::Rect* face_box) {
  if (!selection_.has_value()) return std::nullopt;
  const SelectionMessage& selection = selection_.value();
  if (!selection.valid || selection.exploring || selection.target_id != target_id) {
    return std::nullopt;
  }
  if (selection.boxes_fresh) {
    target_size_id_ = target_id;
    target_size_ = cv::Size(std::max(selection.left_box.width, selection.right_box.width),
                            std::max(selection.left_box.height, selection.right_box.height));
  }
  if (target_size_id_ != target_id || target_size_.area() <= 0) return std::nullopt;
  std::optional<Eigen::Vector2d> at;
  try {
    at =
        vision::CameraModelOf(image).Project(vision::CameraPoseOf(image).inverse() * selection.p_W);
  } catch (const InvalidArgument&) {
    return std::nullopt;  // an image without its camera (a source that does not say)
  }
  if (!at) return std::nullopt;
  const cv::Rect region = BoxAround(at->x(), at->y(), target_size_, track_region_scale_, image);
  if (region.area() <= 0) return std::nullopt;
  *face = target_size_;
  if (face_box != nullptr) *face_box = BoxAround(at->x(), at->y(), target_size_, 1.0, image);
  return region;
}

std::optional<std::vector<std::pair<cv::Rect, cv::Size>>> FaceDetectorComponent::PartnerBands(
    const Image& image) {
  if (!partner_.has_value() || !partner_.value().image) return std::nullopt;
  const FacesMessage& partner = partner_.value();
  const Image& other = *partner.image;
  if (other.metadata().time != image.metadata().time) return std::nullopt;  // not this capture
  std::vector<std::pair<cv::Rect, cv::Size>> bands;
  try {
    const geometry::CameraModel other_model = vision::CameraModelOf(other);
    const geometry::Pose X_WO = vision::CameraPoseOf(other);
    const geometry::CameraModel model = vision::CameraModelOf(image);
    const geometry::Pose X_CW = vision::CameraPoseOf(image).inverse();
    // Points of each face's ray at depths evenly spaced in inverse depth (evenly spaced in
    // disparity): the boxes around their images overlap, and their union holds the band.
    constexpr int kSamples = 8;
    for (const FacesMessage::Face& face : partner.faces) {
      const cv::Rect& box = face.box;
      const std::optional<Eigen::Vector3d> ray =
          other_model.Unproject({box.x + 0.5 * (box.width - 1), box.y + 0.5 * (box.height - 1)});
      if (!ray || !(ray->z() > 1e-6)) return std::nullopt;  // not a ray this search can follow
      cv::Rect band;
      for (int k = 0; k < kSamples; ++k) {
        const double inverse =
            1.0 / partner_min_depth_m_ +
            (1.0 / partner_max_depth_m_ - 1.0 / partner_min_depth_m_) * k / (kSamples - 1);
        const Eigen::Vector3d p_W = X_WO * (*ray / (ray->z() * inverse));
        const std::optional<Eigen::Vector2d> at = model.Project(X_CW * p_W);
        if (!at) continue;  // behind this eye: no face there for it to see
        const cv::Rect around = BoxAround(at->x(), at->y(), box.size(), track_region_scale_, image);
        band = band.area() > 0 ? (band | around) : around;
      }
      if (band.area() > 0) bands.emplace_back(band, box.size());
    }
  } catch (const InvalidArgument&) {
    return std::nullopt;  // an image without its camera (a source that does not say)
  }
  return bands;
}

FacesMessage FaceDetectorComponent::Detect(std::shared_ptr<const Image> image, const Search& search,
                                           bool own_thread) {
  // With a track, the whole image (or the partner's bands) is searched for the other faces
  // (discovery_scale_factor); on a thread of its own, where the discovery lane is not used, at
  // the lane's pyramid level.
  vision::FaceDetector& wide = !search.tracked                ? *detector_
                               : own_thread && lane_detector_ ? *lane_detector_
                               : discovery_detector_          ? *discovery_detector_
                                                              : *detector_;
  const std::vector<vision::FaceDetection> found = Find(*image, search, wide);
  if (track_region_scale_ > 0.0 && track_.has_value()) Remember(found, search);
  return Message(std::move(image), found);
}

std::vector<vision::FaceDetection> FaceDetectorComponent::Find(const Image& image,
                                                               const Search& search,
                                                               vision::FaceDetector& wide) const {
  std::vector<vision::FaceDetection> found;
  if (search.whole) {
    vision::FaceDetector::Search whole;
    whole.regions = {cv::Rect(0, 0, image.width(), image.height())};
    whole.checked = search.checked;
    found = wide.Detect(image, whole);
  }
  // As the whole image would be searched, around each of the partner's faces' bands, and
  // around each of the lane's faces. A face found in a revisit's box is the one the lane found
  // there, moved by what it moved since: it keeps that face's verdict at a third of their union
  // (a box of the same size half its side away), where faces that merely overlap need 70 %.
  const auto search_around = [&](const std::vector<std::pair<cv::Rect, cv::Size>>& boxes,
                                 double verdict_overlap) {
    for (const auto& [band, face] : boxes) {
      vision::FaceDetector::Search along;
      along.regions = {band};
      std::tie(along.min_size_px, along.max_size_px) = SizeBounds(face);
      along.checked = search.checked;
      along.verdict_overlap = verdict_overlap;
      for (const vision::FaceDetection& d : wide.Detect(image, along)) {
        const bool again = std::any_of(found.begin(), found.end(), [&d](const auto& f) {
          return SameFace(f.box, d.box);
        });  // two bands that overlap
        if (!again) found.push_back(d);
      }
    }
  };
  search_around(search.bands, vision::FaceDetector::kVerdictOverlap);
  search_around(search.revisits, kRevisitVerdictOverlap);
  std::vector<cv::Rect> regions;
  if (search.region) regions.push_back(*search.region);
  if (search.predicted) regions.push_back(*search.predicted);
  std::vector<vision::FaceDetection> near;
  if (!regions.empty()) {
    // The tracked face from the regions, at the region's pyramid level.
    vision::FaceDetector::Search around;
    around.regions = regions;
    around.min_size_px = search.min_size_px;
    around.max_size_px = search.max_size_px;
    around.checked = search.checked;
    around.verdict_overlap = search.verdict_overlap;
    near = region_detector_->Detect(image, around);
  }
  return Merge(std::move(found), near);
}

std::vector<vision::FaceDetection> FaceDetectorComponent::Merge(
    std::vector<vision::FaceDetection> whole, const std::vector<vision::FaceDetection>& near) {
  std::erase_if(whole, [&near](const vision::FaceDetection& d) {
    return std::any_of(near.begin(), near.end(),
                       [&d](const vision::FaceDetection& r) { return SameFace(d.box, r.box); });
  });
  whole.insert(whole.end(), near.begin(), near.end());
  std::stable_sort(whole.begin(), whole.end(),
                   [](const auto& a, const auto& b) { return a.box.area() > b.box.area(); });
  return whole;
}

FacesMessage FaceDetectorComponent::Message(std::shared_ptr<const Image> image,
                                            const std::vector<vision::FaceDetection>& found) const {
  FacesMessage out;
  out.image = std::move(image);
  for (const vision::FaceDetection& d : found) {
    out.faces.push_back({d.box, d.neighbors, d.rejected, d.reason});
  }
  return out;
}

void FaceDetectorComponent::Remember(const std::vector<vision::FaceDetection>& found,
                                     const Search& search) {
  std::vector<Verdict> seen;
  for (const vision::FaceDetection& d : found) {
    int reuses = 0;
    if (d.verdict_from >= 0) {
      reuses = search.checked_reuses[d.verdict_from] + 1;
    } else if (std::none_of(verdicts_.begin(), verdicts_.end(),
                            [&d](const Verdict& v) { return SameFace(v.face.box, d.box); })) {
      reuses = recheck_phase_;  // checked for the first time
    }
    seen.push_back({d, reuses, 0});
  }
  // The faces this search did not see (outside the region) are kept until the next whole scan.
  for (const Verdict& v : verdicts_) {
    if (v.age + 1 >= full_scan_every_) continue;
    const bool again = std::any_of(found.begin(), found.end(),
                                   [&v](const auto& d) { return SameFace(v.face.box, d.box); });
    if (!again) seen.push_back({v.face, v.reuses, v.age + 1});
  }
  verdicts_ = std::move(seen);
}

bool FaceDetectorComponent::StartDiscovery(const runtime::StepContext& context,
                                           const std::shared_ptr<const Image>& image,
                                           const Search& search) {
  if (!lane_detector_ || !search.tracked || !search.discovery) return false;
  Search around = search;  // the track's region (or the target's) now, on this thread
  around.whole = false;
  const std::vector<vision::FaceDetection> near = Find(*image, around, *detector_);
  // Unless one is in flight (both eyes start theirs at the same steps: on the same count of
  // detections, or when attention has no target), the whole image on the lane's thread.
  if (!discovery_.valid()) {
    discovery_search_ = search;
    discovery_near_ = near;
    discovery_target_ = last_target_id_;
    discovery_due_ = context.step + discovery_latency_steps_;
    Search wide = search;
    wide.region.reset();
    wide.predicted.reset();
    discovery_ = std::async(std::launch::async, [this, image, wide = std::move(wide)] {
      return Find(*image, wide, *lane_detector_);
    });
  }
  Remember(near, search);
  faces_.Emit(Message(image, near));
  return true;
}

void FaceDetectorComponent::Revisit(const std::vector<vision::FaceDetection>& discovered,
                                    const Image& image, Search* search) const {
  search->whole = false;
  search->discovery = false;
  for (const vision::FaceDetection& d : discovered) {
    const cv::Rect box =
        BoxAround(d.box.x + 0.5 * (d.box.width - 1), d.box.y + 0.5 * (d.box.height - 1),
                  d.box.size(), track_region_scale_, image);
    const bool tracked = search->region && SameFace(*search->region, box);
    if (box.area() > 0 && !tracked) search->revisits.emplace_back(box, d.box.size());
  }
}

void FaceDetectorComponent::Step(const runtime::StepContext& context) {
  const bool own_thread = latency_steps_ > 0 || (context.realtime && realtime_thread_);
  if (!own_thread) {
    // The discovery's faces (of an image D steps old): searched again, each around where it
    // was, in this step's image (waits, in simulated time, for as long as the search takes).
    std::vector<vision::FaceDetection> discovered;
    if (Due(discovery_, context, discovery_due_)) {
      discovered = Merge(discovery_.get(), discovery_near_);
      // A new target meanwhile forgot every verdict (the eyes jumped): these are of before.
      if (last_target_id_ == discovery_target_) Remember(discovered, discovery_search_);
    }
    if (image_.fresh() && image_.value().image) {
      const std::shared_ptr<const Image>& image = image_.value().image;
      Search search = NextSearch(*image);
      // Where the lane found its faces is where they were before the eyes jumped to a new
      // target (since, or at this step): not where this image shows them.
      if (!discovered.empty() && last_target_id_ == discovery_target_) {
        Revisit(discovered, *image, &search);
      }
      if (!StartDiscovery(context, image, search)) faces_.Emit(Detect(image, search));
    }
    return;
  }
  if (running_.valid()) {
    if (!Due(running_, context, due_step_)) return;
    faces_.Emit(running_.get());  // waits, in simulated time, for as long as it takes
  }
  // The newest image: the one this step brought, or a later one than the last detected.
  if (!image_.has_value() || !image_.value().image) return;
  const std::shared_ptr<const Image>& image = image_.value().image;
  if (!image_.fresh() && image == last_) return;
  last_ = image;
  due_step_ = context.step + latency_steps_;
  const Search search = NextSearch(*image);
  running_ =
      std::async(std::launch::async, [this, image, search] { return Detect(image, search, true); });
}

void FaceDetectorComponent::Stop() {
  if (running_.valid()) running_.wait();
  if (discovery_.valid()) discovery_.wait();
}

}  // namespace saccade::components
