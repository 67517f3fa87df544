#pragma once
// vision.face_detector -- Haar or LBP faces with the cat and eye checks
// (vision/face_detector.h).
//   inputs: image (runtime.image, required); track (vision.track, optional: this eye's
//           CamShift track, connect it with delay 1); selection (vision.selection, optional:
//           attention's, with delay 1); partner (vision.faces, optional: the other eye's
//           detector's faces, no delay); outputs: faces (vision.faces), with the image they
//           were found in (its time is their capture time).
//
// With the partner's faces of an image captured at the same time as this one (the other eye
// of the same stereo pair, the cameras' models and poses in both images' metadata), a search
// that would take the whole image takes instead each partner face's epipolar band: the boxes
// `track_region_scale` times the face around where its ray from the other eye, between
// `partner_min_depth_m` and `partner_max_depth_m`, projects in this image, at face sizes within
// `region_size_factor` of it. A face that one eye alone sees cannot be triangulated, so the
// stereo loop loses nothing; the other eye's faces of another capture (a detector on a thread
// of its own), or an image without its camera, leave the whole image searched.
//
// While the track input (when connected) follows a target and `track_region_scale` > 0 (1.8
// by default), the detector searches a box that many times the track's window around it (at
// `region_pyramid_level`), and the whole image too (at `pyramid_level`) every
// `full_scan_every`-th detection, so that attention still sees the other faces (a discovery
// search: at `discovery_scale_factor`, a coarser step between sizes than the search around the
// track's `scale_factor`; the tracked face's box comes from the latter), and on the
// first `new_target_scans` detections of a new target (the track's target_id changed): the
// saccade to it blurs the images and a tracker may slip onto another face meanwhile; a region
// around that face would keep finding it, and the two eyes' faces would not pair again until
// the next whole scan. With the selection input, those detections search instead a box
// `track_region_scale` times the target's face (its boxes when attention selected it) around
// where the selection's 3D point projects in the image (its camera and pose, from the image's
// metadata): the target's face whatever the tracker did, at a fraction of the cost of the
// whole image (which they still search when the image carries no camera).
//
// Around the track it searches only faces of the track window's size to within
// `region_size_factor`. The cat and eye checks are most of a search around a face: a face
// seen again at about the same place keeps its verdict for `recheck_every` - 1 searches (the
// eyes move little between frames while they fixate or pursue; a new target, and the saccade
// to it, forgets every verdict).
// Parameters: declared in the constructor (docs/components.md lists them).
//
// The discovery lane: with discovery_latency_steps D > 0 (and latency_steps 0), the whole-image
// searches that look for the other faces while the track input is connected leave the step:
// every full_scan_every-th detection, and every detection while attention has no target (the
// selection is invalid or looks around), searches at once only around the track (or nothing),
// and the whole image on a thread of its own (its own cascades, at discovery_pyramid_level).
// D steps later (simulated clock: exactly D, so that a run repeats bit for bit; real time: the
// first step after it is done) the faces it found are searched again around where they were
// (boxes track_region_scale times each, at its size), in that step's own image: every faces
// message is of its own step's image, and a whole-image search never holds up the loop. A face
// found there keeps the verdict the lane gave it if their boxes overlap by a third of their
// union (it moved, or was found at another size, since). When the eyes have jumped to a new
// target since the lane began, its faces are not searched again: they are no longer where it
// found them in the image, and the next discovery finds them. Both
// eyes start theirs on the same steps, so that the stereo pairs hold. The right eye's lane
// searches the whole image, not the left faces' bands (the partner has, on that step, only the
// faces around its track). A lost target (the track input not tracking while attention has
// one) is searched for around where the selection's point projects (as a new target is), the
// whole image only when the selection cannot say.
//
// Detect slowly, track fast: with latency_steps N > 0 the detector works on a thread of its
// own, on the newest image it can take, while the loop goes on; its faces are emitted N steps
// after that image arrived (simulated clock: exactly N, so that a run repeats bit for bit) or
// as soon as they are ready (real time), and it then takes the newest image again. Tracking
// and triangulation use the image the faces carry, so late faces are placed where they were.
// On the real-time clock (realtime_thread) the discovery lane is not used, as all detection is
// off the loop's thread; with discovery_latency_steps > 0 the whole-image searches for the
// other faces then take the lane's discovery_pyramid_level.
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "saccade/components/messages.h"
#include "saccade/runtime/component.h"
#include "saccade/vision/face_detector.h"

namespace saccade::components {

class FaceDetectorComponent : public runtime::Component {
 public:
  FaceDetectorComponent();
  void Step(const runtime::StepContext& context) override;
  void Stop() override;

 protected:
  void Configured() override;

 private:
  // Where a detection searches: the whole image (at pyramid_level), a region around the track
  // (at region_pyramid_level), or both (the region's faces replace the whole image's there).
  struct Search {
    bool whole = true;
    bool tracked = false;  // a track region is in use: the whole image is a discovery search
    // With a track input: the full_scan_every-th search, or one while attention has no target
    // (the discovery lane takes those whole-image searches).
    bool discovery = false;
    std::optional<cv::Rect> region;
    std::optional<cv::Rect> predicted;  // around where the selection puts a new target
    // Instead of the whole image, around each of the partner's faces' epipolar bands: the band
    // and the face's size there.
    std::vector<std::pair<cv::Rect, cv::Size>> bands;
    // The discovery lane's faces, each searched again around where it was (Revisit): the box
    // and the face's size there.
    std::vector<std::pair<cv::Rect, cv::Size>> revisits;
    int min_size_px = 0;  // the region's face sides (0: the parameters' bounds)
    int max_size_px = 0;
    std::vector<vision::FaceDetection> checked;  // verdicts to reuse (recheck_every)
    std::vector<int> checked_reuses;             // how often each was reused in a row
    // The overlap (of the union) at which the region's search takes a checked verdict: lower
    // on a new target's scans, where the target's own verdict is among them.
    double verdict_overlap = vision::FaceDetector::kVerdictOverlap;
  };
  // The parameters, declared by what they set: the whole image's search and when and on
  // which thread it runs; the searches the track, selection and partner inputs steer; the
  // cascades' levels, sizes, steps and checks.
  void DeclareImageParams();
  void DeclareTrackParams();
  void DeclareCascadeParams();
  // options_ with the cascades the parameters choose.
  vision::FaceDetector::Options DetectorOptions() const;
  Search NextSearch(const Image& image);
  // Around the track (the n-th detection): the region, the new target's, and whether the
  // whole image too.
  void AroundTrack(const Image& image, int64_t n, Search* search);
  // The face sides searched around a face of this size (region_size_factor); {0, 0}: the
  // parameters' bounds.
  std::pair<int, int> SizeBounds(const cv::Size& face) const;
  // Widens search's face sides to cover `face`'s size to within region_size_factor.
  void SizesAround(const cv::Size& face, Search* search) const;
  // A box track_region_scale times the target's size around where the selection's point
  // projects in `image` (the size in `face`); none without a selection of that target, a
  // known size, or a camera. `face_box`, when given: the target's own box there.
  std::optional<cv::Rect> PredictedRegion(const Image& image, int64_t target_id, cv::Size* face,
                                          cv::Rect* face_box = nullptr);
  // The partner's faces' epipolar bands in `image` (their rays from the other eye between
  // partner_min_depth_m and partner_max_depth_m, projected, each widened as a track region is);
  // none when the partner's faces are not of an image captured with this one or a camera is
  // unknown (then the whole image is searched).
  std::optional<std::vector<std::pair<cv::Rect, cv::Size>>> PartnerBands(const Image& image);
  // The faces of `image` (own_thread: on the detector's thread, latency_steps or
  // realtime_thread), remembered for the next search.
  FacesMessage Detect(std::shared_ptr<const Image> image, const Search& search,
                      bool own_thread = false);
  // The faces of `image`: the whole image's (or the bands') with `wide`, then the regions',
  // which replace the boxes they overlap; largest first. Touches no member but the detectors.
  std::vector<vision::FaceDetection> Find(const Image& image, const Search& search,
                                          vision::FaceDetector& wide) const;
  // The regions' faces merged into the whole image's (the regions' replace those they overlap),
  // largest first.
  static std::vector<vision::FaceDetection> Merge(std::vector<vision::FaceDetection> whole,
                                                  const std::vector<vision::FaceDetection>& near);
  FacesMessage Message(std::shared_ptr<const Image> image,
                       const std::vector<vision::FaceDetection>& found) const;
  void Remember(const std::vector<vision::FaceDetection>& found, const Search& search);
  // When `search` is a discovery search and the lane is on: searches around the track now,
  // emits those faces and starts the whole image on the lane (unless a search is in flight
  // there). False when it is not one: the caller searches.
  bool StartDiscovery(const runtime::StepContext& context,
                      const std::shared_ptr<const Image>& image, const Search& search);
  // Turns `search` of this step's image into one around each of the discovered faces (boxes
  // track_region_scale times each, at its size), the track's region kept.
  void Revisit(const std::vector<vision::FaceDetection>& discovered, const Image& image,
               Search* search) const;

  vision::FaceDetector::Options options_;
  std::string cascade_ = "haar";
  bool reject_cats_ = true;
  bool require_eyes_ = true;
  int latency_steps_ = 0;
  bool realtime_thread_ = true;
  double track_region_scale_ = 1.8;
  int full_scan_every_ = 20;
  int region_pyramid_level_ = 0;
  int new_target_scans_ = 5;
  bool keep_target_verdict_ = true;
  double region_size_factor_ = 1.5;
  int recheck_every_ = 10;
  int recheck_phase_ = 0;
  int discovery_latency_steps_ = 0;
  int discovery_pyramid_level_ = 0;
  double discovery_scale_factor_ = 1.2;
  double partner_min_depth_m_ = 0.3;
  double partner_max_depth_m_ = 20.0;
  // The faces seen lately and their verdicts: `reuses` searches in a row took the verdict
  // without checking again; `age` searches have not seen the face since. Written by Detect (on
  // the detection's thread when it has one; NextSearch reads them once it has been collected).
  struct Verdict {
    vision::FaceDetection face;
    int reuses = 0;
    int age = 0;
  };
  std::vector<Verdict> verdicts_;
  int64_t detections_ = 0;       // started so far
  int64_t last_target_id_ = -1;  // the track's target at the last detection
  int whole_scans_left_ = 0;     // of new_target_scans
  // The detection in flight (on its own thread) and the step its faces are due.
  std::future<FacesMessage> running_;
  int64_t due_step_ = 0;
  std::shared_ptr<const Image> last_;  // the image detected last
  // The discovery lane's search in flight: the whole image's faces; the search it is part of
  // and that search's faces around the track (found at once); the step they are due.
  std::future<std::vector<vision::FaceDetection>> discovery_;
  Search discovery_search_;
  std::vector<vision::FaceDetection> discovery_near_;
  int64_t discovery_due_ = 0;
  int64_t discovery_target_ = -1;  // the track's target when it started
  runtime::Input<runtime::ImageMessage>& image_;
  runtime::Input<TrackMessage>& track_;
  runtime::Input<SelectionMessage>& selection_;
  runtime::Input<FacesMessage>& partner_;
  int64_t target_size_id_ = -1;  // the target whose face size is known
  cv::Size target_size_;         // its boxes' size when last detected
  runtime::Output<FacesMessage>& faces_;
  std::unique_ptr<vision::FaceDetector> detector_;         // the whole image
  std::unique_ptr<vision::FaceDetector> region_detector_;  // around the track
  // The whole image once a track came (discovery_scale_factor), when it differs from
  // scale_factor.
  std::unique_ptr<vision::FaceDetector> discovery_detector_;
  // The discovery lane's (discovery_latency_steps > 0): its thread's own cascades.
  std::unique_ptr<vision::FaceDetector> lane_detector_;
};

}  // namespace saccade::components
