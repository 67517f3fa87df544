#pragma once
// The OpenGL renderer's class and the parts its files share (private to render/gl):
//   internal_gl_renderer.cc  set-up, programs, lights, Submit, the effect passes, Render
//   internal_draw.cc         the colour pass and the truth pass, through one item visitor
//   internal_readback.cc     Retrieve: one readback path for every camera, the metadata
//   internal_truth.cc        depth, ids and each object's box and pose
//   internal_pixels.cc       RGBA to RGB
#include <epoxy/gl.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "render/gl/internal_camera_target.h"
#include "render/gl/internal_color_depth.h"
#include "render/gl/internal_cpu_turn.h"
#include "render/gl/internal_effects.h"
#include "render/gl/internal_egl_context.h"
#include "render/gl/internal_gl_util.h"
#include "render/gl/internal_gpu_resources.h"
#include "render/gl/internal_pixels.h"
#include "saccade/core/error.h"
#include "saccade/head/kinematics.h"
#include "saccade/render/camera_chain.h"
#include "saccade/render/renderer.h"
#include "saccade/render/sensor_model.h"

namespace saccade::render::gl {

using Clock = std::chrono::steady_clock;

inline double Milliseconds(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}

// Per-vertex (Gouraud) lighting is used on meshes whose mean edge is at most this long on
// screen: over a triangle that small, interpolated lighting and per-fragment lighting differ
// by far less than one 8-bit step for smooth surfaces (internal_shaders.h).
inline constexpr double kPerVertexMaxEdgePx = 2.0;

// Images kept per camera for reuse once the caller has let go of them (no allocation and no
// page faults per frame in steady state).
inline constexpr std::size_t kPooledImagesPerCamera = 4;

// Every link of the robot's tree in the world for a state's joints (the home posture when the
// state has none).
using LinkPoses = std::vector<geometry::Pose>;
inline LinkPoses RobotLinkPoses(const scene::Robot& robot, const head::JointState& joints) {
  LinkPoses X_WL;
  robot.head.ForwardKinematics(robot.head.Posture(joints), &X_WL);
  return X_WL;
}

// The pose of a robot part's link in a state.
inline const geometry::Pose& LinkPose(const LinkPoses& X_WL, int link) { return X_WL[link]; }

// Uniform locations of the lights, common to every program.
struct LightUniforms {
  GLint ambient = -1, directional_direction = -1, directional_color = -1, point_position = -1,
        point_color = -1;
  void Find(GLuint program) {
    ambient = Uniform(program, "u_ambient");
    directional_direction = Uniform(program, "u_directional_direction");
    directional_color = Uniform(program, "u_directional_color");
    point_position = Uniform(program, "u_point_position");
    point_color = Uniform(program, "u_point_color");
  }
};

// Variant bits of the mesh program (internal_shaders.h).
enum MeshVariant : int { kTextured = 1, kShiny = 2, kPerVertex = 4, kTwoSided = 8 };

struct MeshProgram {
  GLuint program = 0;
  GLint mvp = -1, mv = -1, normal = -1;
  GLint base_color = -1, specular = -1, shininess = -1;
  LightUniforms lights;
  int64_t lights_pass = -1;  // the camera pass whose lights are set
};

struct GroundProgram {
  GLuint program = 0;
  GLint mvp = -1, mv = -1, normal_eye = -1;
  LightUniforms lights;
};

// Something drawn with the mesh programs: an object or a robot part.
struct DrawItem {
  const GpuModel* model = nullptr;
  int object = -1;  // index into scene.objects(), or -1 for a robot part
  int part = -1;    // index into robot.parts
  Eigen::Vector3d scale{1.0, 1.0, 1.0};
  Eigen::Vector3d center_model = Eigen::Vector3d::Zero();  // bounds centre (model frame)
  double radius_model = 0.0;  // about center_model to the farthest vertex, scaled
};

// Column-major float copy of a double matrix, for glUniformMatrix*.
template <int N>
std::array<float, N * N> ToFloat(const Eigen::Matrix<double, N, N>& m) {
  std::array<float, N * N> out;
  Eigen::Map<Eigen::Matrix<float, N, N>>(out.data()) = m.template cast<float>();
  return out;
}

// The 8 corners of `box` all lie outside one plane of the clip volume.
inline bool OutsideFrustum(const Eigen::Matrix4d& mvp, const Eigen::AlignedBox3f& box) {
  int outside[6] = {0, 0, 0, 0, 0, 0};
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3f c = box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(corner));
    const Eigen::Vector4d p = mvp * Eigen::Vector4d(c.x(), c.y(), c.z(), 1.0);
    outside[0] += p.x() < -p.w();
    outside[1] += p.x() > p.w();
    outside[2] += p.y() < -p.w();
    outside[3] += p.y() > p.w();
    outside[4] += p.z() < -p.w();
    outside[5] += p.z() > p.w();
  }
  return std::any_of(std::begin(outside), std::end(outside), [](int n) { return n == 8; });
}

// Maps a slot's pixel buffer for reading; throws, naming the GL error, when it cannot (the
// buffer is then unmapped). `what` follows "glMapBufferRange failed" in the message.
template <class Buffers>
const uint8_t* MapOrThrow(const Buffers& buffers, int slot, const char* what) {
  const auto* pixels = static_cast<const uint8_t*>(buffers.Map(slot));
  if (pixels == nullptr) {
    const GLenum error = glGetError();
    buffers.Unmap();
    throw Error(std::string("Renderer::Retrieve: glMapBufferRange failed") + what + ": " +
                GlErrorName(error));
  }
  return pixels;
}

// The noise stream of one camera and frame: its seed, its name and the frame index.
uint32_t NoiseKey(uint64_t seed, const std::string& camera, int64_t frame_index);

// One camera's source view as drawn: projection, focal length (for levels of detail), the
// view's orientation in the camera, and the camera's +z in the view's OpenGL eye frame.
struct ViewSetup {
  Eigen::Matrix4d projection;
  double focal = 0.0;
  Eigen::Matrix3d R_CV = Eigen::Matrix3d::Identity();
  Eigen::Vector3f depth_axis{0.0f, 0.0f, -1.0f};
};

class GlRenderer final : public Renderer {
 public:
  GlRenderer(const scene::Scene& scene, const RendererOptions& options,
             const std::vector<std::string>& camera_names);
  ~GlRenderer() override;

  std::vector<Frame> Render(const scene::SceneState& state, int64_t frame_index) override;
  void Submit(const scene::SceneState& state, int64_t frame_index) override;
  std::vector<Frame> Retrieve() override;
  int InFlight() const override { return in_flight_; }
  void SetEffects(const EffectSwitches& effects) override;
  // Batch rendering (internal_batch.cc).
  void RenderBatch(const std::vector<BatchHead>& heads, uint8_t* out,
                   std::size_t out_bytes) override;
  const std::vector<std::string>& camera_names() const override { return camera_names_; }
  std::string DeviceDescription() const override { return description_; }
  const RenderStats& stats() const override { return stats_; }

 private:
  struct CameraSetup;
  void BuildCameraSetups(std::vector<CameraSetup> reuse = {}, bool reuse_distortion = false);
  // Set-up (the constructor's parts): the scene's lights by kind (throws beyond kMaxLights);
  // the GPU resources and where each effect runs, for the device `renderer` names; the items
  // and the ground with their programs; the GL state every pass keeps.
  void SortLights();
  void ChooseDevicePaths(const std::string& renderer);
  void AddItems();
  void SetFixedState();
  void PrebuildFinal(const CameraSetup& setup);
  // A submitted state whose pixels are on their way.
  struct Pending {
    scene::SceneState state;
    int64_t frame_index = 0;
    std::vector<geometry::Pose> X_WC;   // per camera
    std::vector<int> exposure_samples;  // per camera: sub-frames drawn (1: an instant)
    // Per camera: the noise Retrieve adds to the pixels read back (the final pass skipped).
    std::vector<std::optional<NoiseParams>> cpu_noise;
    // Per camera: its source view was read back for the lens remap on the CPU (the pass
    // skipped; EffectTarget::cpu_lens).
    std::vector<bool> cpu_lens;
    // Per camera: its stretches were read back for the turn's fetches on the CPU (the pass
    // skipped; RendererOptions::turn_blur_on_cpu).
    std::vector<std::optional<CpuTurn>> cpu_turn;
    GLsync fence = nullptr;
  };

  // How one camera renders.
  struct CameraSetup {
    std::vector<ViewSetup> views;
    std::unique_ptr<EffectTarget> effects;  // null: the plain path (CameraTarget only)
    bool distorted = false;                 // the frames carry the lens's distortion
    std::shared_ptr<const geometry::CameraModel> rendered;  // every frame's camera model
    bool noise = false;  // the legacy noise in the final pass or fused with the readback
    bool blur = false;   // blur configured (sub-frames as many as the image motion needs)
    // The photometric chain (vignetting, depth of field, colour; null: none of them), and
    // whether the legacy noise comes after its optics, on the CPU (`noise` is then false).
    std::unique_ptr<CameraChain> chain;
    bool late_noise = false;
    // Depth is needed: truth asked, or the depth of field's depth (the truth pass's, or the
    // colour pass's when the effect target has_color_depth, through color_depth).
    bool truth = false;
    ColorDepthMap color_depth;
    std::vector<float> color_depth_source_z;  // ColorPassDepth's source-size buffer
  };
  // The chain of camera `i` (setup.rendered made), and the noise and truth it implies.
  void SetChain(std::size_t i, CameraSetup* setup) const;

  MeshProgram& GetMeshProgram(int variant);
  void BuildGroundProgram();
  void AddItem(const scene::Model& model, const Eigen::Vector3d& scale, int object, int part);
  void UpdatePoses(const scene::SceneState& state);
  // The colour pass and the truth pass (internal_draw.cc) draw the same items in the same
  // order at the same levels of detail, through one visitor.
  // `cull`: draw only the items inside the frustum of cull * mvp too (a part of the view).
  void DrawScene(const ViewSetup& view, double near, const geometry::Pose& X_WV,
                 const Eigen::Matrix4d* cull = nullptr);
  void DrawTruth(const ViewSetup& view, double near, const geometry::Pose& X_WV);
  template <class Visit>
  void ForEachVisibleItem(const ViewSetup& view, double near, const Eigen::Isometry3d& X_EW,
                          Visit&& visit, const Eigen::Matrix4d* cull = nullptr);
  const GpuLod& LodOf(const GpuMesh& mesh, double px_per_model_unit) const;
  static void DrawLod(const GpuMesh& mesh, const GpuLod& lod, bool* culling);
  void DrawGround(GLint mvp, GLint mv, const Eigen::Matrix4d& P, const Eigen::Isometry3d& X_EW);
  // Readback (internal_readback.cc): the frame's metadata, and truth (internal_truth.cc).
  void Describe(int camera, const Pending& pending, ImageMetadata* meta) const;
  // The effect path of one camera: its exposure's sub-frames drawn (one instant, every
  // sub-frame, or a turning camera's stretches), its truth, then the final pass or the
  // readback that stands for it into `slot`.
  void DrawEffects(int camera, const scene::SceneState& state, int64_t frame_index,
                   const geometry::Pose& X_WC, int slot);
  // How a camera's exposure is drawn in one frame (PlanExposure).
  struct ExposurePlan {
    std::vector<scene::SceneState> sub_states;  // motion blur's sub-frames; empty: one instant
    int samples = 1;                            // sub-frames (1: one instant)
    double camera_px = 0.0;       // the camera's own share of the image motion (ImageMotionPx)
    std::vector<double> item_px;  // and each item's
    double turn_only_px = 0.0;    // how far the image departs from the camera's turn alone
    int stretches = 0;            // a turning camera's stretches; 0: every sub-frame drawn
  };
  ExposurePlan PlanExposure(int camera, const scene::SceneState& state) const;
  // A turning camera's stretches, each drawn at its middle: into the stretch layers, their
  // sub-frames' homographies added to `turn` (fused into the final pass); or, `turn` null,
  // into the source view, accumulated through the homographies (TurnBlur). The colour
  // depth, where the target reads it, is the middle stretch's, into `slot`.
  void DrawTurnStretches(int camera, const scene::SceneState& state, const ExposurePlan& plan,
                         TurnSamples* turn, int slot);
  // Every sub-frame drawn and accumulated (with the camera still, only the moving items'
  // regions redrawn after the first, then written back); whether the final pass reads the
  // accumulation. The poses are `state`'s again after. The colour depth, where the target
  // reads it, is the sub-frame drawn first's (the middle one), into `slot`.
  bool DrawSubFrames(int camera, const scene::SceneState& state, const ExposurePlan& plan,
                     int slot);
  // The final pass, or the readback that replaces it where the CPU finishes the image (noise,
  // lens remap, a turn's fetches). `turn`: the stretches' homographies when fused, else null.
  void FinishEffects(int camera, int64_t frame_index, int slot, bool accumulated, TurnSamples* turn,
                     int stretches);
  // How far, at most, anything the camera sees moves on its image between s0 and s1
  // (pixels, a bound through the pinhole of K): motion blur draws that many sub-frames.
  // `camera_px`, when given, gets the camera's own share (its turn and shift), `item_px` each
  // item's bound (0 for items out of view), `turn_only_px` a bound on how far the image
  // between s0 and s1 departs from the camera's turn alone (a homography): the parallax of its
  // shift (its sideways and its axial part apart) at the nearest depth it sees, plus the
  // items' own motion in the world.
  double ImageMotionPx(int camera, const scene::SceneState& s0, const scene::SceneState& s1,
                       double* camera_px = nullptr, std::vector<double>* item_px = nullptr,
                       double* turn_only_px = nullptr) const;
  struct MotionGains;
  struct CameraMotion;
  // One item's share of ImageMotionPx, at X_WO0 and X_WO1: its bound, or nullopt when it is
  // out of view at both ends; `off_turn`, when given, raised to its departure from the turn.
  std::optional<double> ItemMotionPx(const DrawItem& item, const geometry::Pose& X_WO0,
                                     const geometry::Pose& X_WO1, const MotionGains& gains,
                                     const CameraMotion& camera,
                                     const std::vector<ViewSetup>& views, double* off_turn) const;
  // Motion blur's sub-frames with the camera still: per view of the camera, the window
  // rectangle (x, y, width, height) outside which every sub-frame equals sub-frame `whole`
  // (the items that move by a pixel or more, by `item_px`, do not reach there), or nullopt for
  // all of the view (a moving item reaches behind the eye).
  using Region = std::array<int, 4>;
  std::vector<std::optional<Region>> MovingRegions(int camera,
                                                   const std::vector<scene::SceneState>& subs,
                                                   std::size_t whole,
                                                   const std::vector<double>& item_px) const;
  // The items that move by a pixel or more (by `item_px`) over sub-frames `subs`, each with
  // its pose at every sub-frame (world frame).
  using MovingPoses = std::vector<std::pair<const DrawItem*, geometry::Pose>>;
  MovingPoses MovingItems(const std::vector<scene::SceneState>& subs,
                          const std::vector<double>& item_px) const;
  geometry::Pose ItemPose(const DrawItem& item, const scene::SceneState& state,
                          const std::optional<LinkPoses>& frames) const;
  // Eye frame from world, and the pixels per model unit at an item's nearest point.
  static Eigen::Isometry3d EyeFromWorld(const geometry::Pose& X_WV);
  void SortItems(const Eigen::Isometry3d& X_EW);
  double PixelsPerModelUnit(const DrawItem& item, double depth, double focal, double near) const;
  // `depth`, when not null, receives the depth image whether or not the frame asks for it
  // (the depth of field's).
  void FillTruth(int camera, const Pending& pending, int slot, Frame* frame,
                 std::shared_ptr<Image>* depth);
  // The depth of field's depth from the colour pass's depth buffer read back into `slot`
  // (EffectTarget::ReadColorDepth): the camera's z at its size, 0 where no surface.
  std::shared_ptr<Image> ColorPassDepth(int camera, int slot, const Image& color);
  // The photometric chain of a frame read back, in place, light first: the lens (vignetting,
  // depth of field from the job's depth), the legacy noise when it comes after them, the EMVA
  // sensor, then the colour (the raw mosaic into frame->raw). ApplyChains runs it for every
  // camera that has any of it (HasChainWork), two cameras at once where there are two cores:
  // what a camera's chain touches is its own (LevelsFor and the sensor models' slots are made
  // before), and the time goes into RenderStats::cpu_effects_ms.
  struct ChainJob {
    Image* image = nullptr;
    std::shared_ptr<Image> depth;     // the depth of field's
    const uint8_t* levels = nullptr;  // the late noise's NoiseLevels
    int64_t frame_index = 0;
    scene::AppliedControls controls;  // the frame's exposure, gain and focus
  };
  bool HasChainWork(int camera, const ChainJob& job) const;
  void ApplyChains(std::vector<ChainJob>* jobs, std::vector<Frame>* frames);
  void ApplyChain(int camera, const ChainJob& job, Frame* frame);
  // The legacy noise of a camera (the final pass's, bit for bit) on an RGB image in place.
  NoiseParams LateNoiseParams(int camera, int64_t frame_index) const;
  void ApplyLateNoise(int camera, int64_t frame_index, const uint8_t* levels, Image* image) const;
  uint32_t ItemId(const DrawItem& item) const;
  // The lights' colours and the ambient term, once when a program is built (the program in
  // use); SetLights then sends what moves with the camera, each camera pass: directions and
  // positions in its eye frame.
  void SetLightColours(const LightUniforms& uniforms) const;
  void SetLights(const LightUniforms& uniforms, const Eigen::Isometry3d& X_EW) const;
  std::shared_ptr<Image> NewImage(int camera);
  // The CPU's share of Retrieve (internal_readback.cc): NoiseLevels for a sensor, made once;
  // rows [first_row, end_row) of a camera's image from the pixels read back, remapped through
  // its lens (`lens`: Pending::cpu_lens) or through its turn (`turn`: Pending::cpu_turn,
  // null: none) and with its noise (null: none; one of them at least).
  const uint8_t* LevelsFor(const NoiseParams& noise);
  // A camera's EMVA 1288 sensor (scene::SensorSpec::emva) on its colour frame, in place: on
  // the CPU after readback, on every device (render/sensor_model.h); the model made once. With
  // the frame's commanded exposure and gain (`controls`); without an EMVA sensor (or with the
  // noise off) a commanded exposure and gain scale the 8-bit values instead
  // (AppliedControls::BrightnessFactor); nothing commanded: nothing changes.
  void ApplySensor(int camera, const scene::AppliedControls& controls, Image* image);
  void ConvertRows(int camera, bool lens, const CpuTurn* turn, const uint8_t* pixels,
                   const CpuNoise* noise, Image* image, int first_row, int end_row) const;

  EglContext context_;  // first: destroyed last
  scene::Scene scene_;
  RendererOptions options_;
  std::vector<const scene::CameraSpec*> cameras_;
  std::vector<std::string> camera_names_;
  std::vector<Eigen::Matrix4d> projections_;
  std::unique_ptr<GpuResources> resources_;
  std::vector<std::unique_ptr<CameraTarget>> targets_;  // plain path, per camera (or null)
  std::vector<CameraSetup> setups_;                     // per camera
  std::unique_ptr<EffectPrograms> effect_programs_;
  bool truth_ = false;  // ids and depth rendered
  std::map<int, MeshProgram> mesh_programs_;
  GroundProgram ground_;
  GLuint ground_vao_ = 0;
  bool draw_ground_ = false;
  bool draw_robot_ = false;
  double turn_blur_max_error_px_ = -1.0;  // RendererOptions::turn_blur*; < 0: off
  bool noise_on_cpu_ = false;             // RendererOptions::noise_on_cpu, resolved
  bool lens_on_cpu_ = false;              // RendererOptions::lens_on_cpu, resolved
  bool turn_on_cpu_ = false;              // RendererOptions::turn_blur_on_cpu, resolved
  // NoiseLevels by (read sigma, gain), made as cameras need them.
  std::map<std::pair<float, float>, std::vector<uint8_t>> noise_levels_;
  // Per camera: its EMVA 1288 sensor, made at its first frame (null: none yet, or none).
  std::vector<std::unique_ptr<SensorModel>> sensor_models_;
  std::vector<DrawItem> items_;
  std::vector<Eigen::Isometry3d> item_poses_;  // X_WO (X_WLink X_LinkPart) per item, this state
  std::vector<std::pair<double, int>> order_;  // per view: depth, item
  Eigen::Vector3f ambient_ = Eigen::Vector3f::Zero();
  std::vector<const scene::Light*> directional_lights_;
  std::vector<const scene::Light*> point_lights_;
  std::array<Pending, CameraTarget::kSlots> pending_;
  std::vector<std::vector<std::shared_ptr<Image>>> image_pools_;  // per camera
  int64_t camera_pass_ = 0;                                       // counts DrawScene calls
  int oldest_ = 0;
  int in_flight_ = 0;
  int samples_ = 0;
  std::string description_;
  RenderStats stats_;
  // The batch's framebuffer (internal_batch.cc): a colour texture array of one layer per
  // tile, every tile drawn at the origin of its layer (as a batch of one head is), a depth
  // buffer of one tile, and the pixel buffer the tiles are read into; made on the first
  // RenderBatch and remade when a batch has more tiles; freed with the context.
  struct BatchTarget {
    GLuint framebuffer = 0, color = 0, depth = 0, pixels = 0;
    int layers = 0;  // of `color`
    std::size_t pixel_bytes = 0;
  };
  BatchTarget batch_;
  std::vector<ViewSetup> batch_views_;  // per camera: the pinhole of its K
  // Draws tiles [first, last) of a batch (tile = head * cameras + camera) and reads them back
  // into their place in `out` (internal_batch.cc).
  void DrawBatchTiles(const std::vector<BatchHead>& heads, std::size_t first, std::size_t last,
                      uint8_t* out);
  // Its parts: the layers a part of a batch of `count` tiles draws at once, the framebuffer of
  // layers and the pixel buffer (re)made when the batch outgrows them (MakeBatchTarget: at
  // least `layers` layers and `pixel_bytes` bytes), and the cameras' views on the first batch;
  // a head's poses (its objects placed or hidden); tiles [first, first + count) of the pixel
  // buffer mapped and converted to RGB into their place in `out`.
  int PrepareBatchTarget(std::size_t count);
  void MakeBatchTarget(int layers, std::size_t pixel_bytes);
  void PoseBatchHead(const BatchHead& head);
  void ConvertBatchPixels(std::size_t first, std::size_t count, uint8_t* out);
  // The second context of RenderBatch (RendererOptions::batch_contexts): a renderer of the
  // same scene on a thread of its own, made on the first batch of two images or more.
  class BatchHelper;
  struct BatchHelperDeleter {
    void operator()(BatchHelper* helper) const;
  };
  int batch_contexts_ = 1;  // RendererOptions::batch_contexts, resolved
  std::unique_ptr<BatchHelper, BatchHelperDeleter> batch_helper_;  // last: destroyed first
};

}  // namespace saccade::render::gl
