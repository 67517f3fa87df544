#include "render/gl/internal_gl_renderer.h"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstring>
#include <map>
#include <optional>
#include <utility>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "render/gl/internal_camera_target.h"
#include "render/gl/internal_effects.h"
#include "render/gl/internal_egl_context.h"
#include "render/gl/internal_gl_util.h"
#include "render/gl/internal_gpu_resources.h"
#include "render/gl/internal_lod.h"
#include "render/gl/internal_shaders.h"
#include "saccade/core/error.h"
#include "saccade/geometry/gl_projection.h"
#include "saccade/geometry/lens_map.h"
#include "saccade/head/kinematics.h"

namespace saccade::render::gl {
namespace {

using Clock = std::chrono::steady_clock;

double Milliseconds(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}

// Per-vertex (Gouraud) lighting is used on meshes whose mean edge is at most this long on
// screen: over a triangle that small, interpolated lighting and per-fragment lighting differ
// by far less than one 8-bit step for smooth surfaces (internal_shaders.h).
constexpr double kPerVertexMaxEdgePx = 2.0;

// Images kept per camera for reuse once the caller has let go of them (no allocation and no
// page faults per frame in steady state).
constexpr std::size_t kPooledImagesPerCamera = 4;

// The pose of a robot part's link in a state.
const geometry::Pose& LinkPose(const head::HeadFrames& frames, scene::RobotPart::Link link) {
  switch (link) {
    case scene::RobotPart::Link::kBase:
      return frames.X_WB;
    case scene::RobotPart::Link::kNeck:
      return frames.X_WN;
    case scene::RobotPart::Link::kCyclopean:
      return frames.X_WC;
    case scene::RobotPart::Link::kLeftEye:
      return frames.X_WL;
    case scene::RobotPart::Link::kRightEye:
      return frames.X_WR;
  }
  return frames.X_WB;
}

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
  double radius_model = 0.0;                               // bounds half diagonal, scaled
};

// Column-major float copy of a double matrix, for glUniformMatrix*.
template <int N>
std::array<float, N * N> ToFloat(const Eigen::Matrix<double, N, N>& m) {
  std::array<float, N * N> out;
  Eigen::Map<Eigen::Matrix<float, N, N>>(out.data()) = m.template cast<float>();
  return out;
}

// The 8 corners of `box` all lie outside one plane of the clip volume.
bool OutsideFrustum(const Eigen::Matrix4d& mvp, const Eigen::AlignedBox3f& box) {
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

// RGBA rows to tightly packed RGB (alpha dropped), portable: four pixels at a time, 16 bytes
// in, 12 bytes out, as three little-endian 32-bit words.
void RgbaToRgbPortable(const uint8_t* rgba, uint8_t* rgb, std::size_t pixels) {
  static_assert(std::endian::native == std::endian::little);
  std::size_t i = 0;
  for (; i + 4 <= pixels; i += 4, rgba += 16, rgb += 12) {
    uint32_t p[4];
    std::memcpy(p, rgba, 16);
    const uint32_t out[3] = {(p[0] & 0x00FFFFFFu) | (p[1] << 24),
                             ((p[1] >> 8) & 0x0000FFFFu) | (p[2] << 16),
                             ((p[2] >> 16) & 0x000000FFu) | (p[3] << 8)};
    std::memcpy(rgb, out, 12);
  }
  for (; i < pixels; ++i, rgba += 4, rgb += 3) {
    rgb[0] = rgba[0];
    rgb[1] = rgba[1];
    rgb[2] = rgba[2];
  }
}

#if defined(__x86_64__)
// The same with one SSSE3 byte shuffle per four pixels (x86-64 CPUs have had SSSE3 since
// 2006; chosen at run time). Each 16-byte store overlaps the next by 4 bytes, so the last
// pixels go through the portable loop to stay inside `rgb`.
__attribute__((target("ssse3"))) void RgbaToRgbSsse3(const uint8_t* rgba, uint8_t* rgb,
                                                     std::size_t pixels) {
  const __m128i shuffle = _mm_setr_epi8(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1);
  std::size_t i = 0;
  for (; i + 6 <= pixels; i += 4, rgba += 16, rgb += 12) {
    const __m128i in = _mm_loadu_si128(reinterpret_cast<const __m128i*>(rgba));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(rgb), _mm_shuffle_epi8(in, shuffle));
  }
  RgbaToRgbPortable(rgba, rgb, pixels - i);
}
#endif

void RgbaToRgb(const uint8_t* rgba, uint8_t* rgb, std::size_t pixels) {
#if defined(__x86_64__)
  static const bool ssse3 = __builtin_cpu_supports("ssse3");
  if (ssse3) return RgbaToRgbSsse3(rgba, rgb, pixels);
#endif
  RgbaToRgbPortable(rgba, rgb, pixels);
}

// SplitMix64's finaliser (S. Vigna): a bijective 64-bit mix.
uint64_t Mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// The noise stream of one camera and frame: its seed, its name (FNV-1a) and the frame index.
uint32_t NoiseKey(uint64_t seed, const std::string& camera, int64_t frame_index) {
  uint64_t name = 0xcbf29ce484222325ull;
  for (const char c : camera) name = (name ^ static_cast<uint8_t>(c)) * 0x100000001b3ull;
  const uint64_t key = Mix64(Mix64(Mix64(seed) ^ name) ^ static_cast<uint64_t>(frame_index));
  return static_cast<uint32_t>(key ^ (key >> 32));
}

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
  const std::vector<std::string>& camera_names() const override { return camera_names_; }
  std::string DeviceDescription() const override { return description_; }
  const RenderStats& stats() const override { return stats_; }

 private:
  // A submitted state whose pixels are on their way.
  struct Pending {
    scene::SceneState state;
    int64_t frame_index = 0;
    std::vector<geometry::Pose> X_WC;  // per camera
    GLsync fence = nullptr;
  };

  // How one camera renders.
  struct CameraSetup {
    std::vector<ViewSetup> views;
    std::unique_ptr<EffectTarget> effects;  // null: the plain path (CameraTarget only)
    bool distorted = false;                 // the frames carry the lens's distortion
    bool noise = false;
    bool blur = false;  // blur configured (it renders sub-frames only when something moves)
  };

  MeshProgram& GetMeshProgram(int variant);
  void BuildGroundProgram();
  void AddItem(const scene::Model& model, const Eigen::Vector3d& scale, int object, int part);
  void UpdatePoses(const scene::SceneState& state);
  void DrawScene(const ViewSetup& view, double near, const geometry::Pose& X_WV);
  void DrawTruth(const ViewSetup& view, double near, const geometry::Pose& X_WV);
  void DrawEffects(int camera, const scene::SceneState& state, int64_t frame_index,
                   const geometry::Pose& X_WC, int slot);
  bool MovesDuringExposure(int camera, const scene::SceneState& state,
                           const std::vector<scene::SceneState>& sub_states) const;
  // Eye frame from world, and the pixels per model unit at an item's nearest point.
  static Eigen::Isometry3d EyeFromWorld(const geometry::Pose& X_WV);
  void SortItems(const Eigen::Isometry3d& X_EW);
  double PixelsPerModelUnit(const DrawItem& item, double depth, double focal, double near) const;
  void FillTruth(int camera, const Pending& pending, int slot, Frame* frame);
  uint32_t ItemId(const DrawItem& item) const;
  void SetLights(const LightUniforms& uniforms, const Eigen::Isometry3d& X_EW) const;
  std::shared_ptr<Image> NewImage(int camera);

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
};

GlRenderer::GlRenderer(const scene::Scene& scene, const RendererOptions& options,
                       const std::vector<std::string>& camera_names)
    : scene_(scene), options_(options), camera_names_(camera_names) {
  for (const std::string& name : camera_names_) {
    const scene::CameraSpec* camera = scene_.FindCamera(name);
    SACCADE_ASSERT(camera != nullptr, "MakeRenderer checked the camera names");
    cameras_.push_back(camera);
  }
  for (const scene::Light& light : scene_.lights()) {
    if (light.type == scene::Light::Type::kAmbient) {
      ambient_ += light.color * light.intensity;
    } else if (light.type == scene::Light::Type::kDirectional) {
      directional_lights_.push_back(&light);
    } else {
      point_lights_.push_back(&light);
    }
  }
  if (directional_lights_.size() + point_lights_.size() > static_cast<std::size_t>(kMaxLights)) {
    throw InvalidArgument(fmt::format(
        "MakeRenderer: the scene has {} directional and point lights; the renderer draws at "
        "most {} (plus any number of ambient lights)",
        directional_lights_.size() + point_lights_.size(), kMaxLights));
  }

  // Multisampling: as many samples as asked, or the device's maximum when it has fewer
  // (llvmpipe has 4); DeviceDescription says which.
  GLint max_samples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  samples_ = std::min(options_.msaa_samples, static_cast<int>(max_samples));

  const std::string version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  const std::string renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  // Software rasterisers implement anisotropic filtering as an elliptical weighted average
  // that is slow and, where texels map about 1:1 (or 2^k:1) to pixels, moves fine texture
  // detail by up to 0.08 px with the sub-pixel phase (measured on llvmpipe and softpipe):
  // trilinear filtering only there.
  const bool software = renderer.find("llvmpipe") != std::string::npos ||
                        renderer.find("softpipe") != std::string::npos;
  resources_ = std::make_unique<GpuResources>(/*anisotropic=*/!software);

  for (std::size_t i = 0; i < scene_.objects().size(); ++i) {
    const scene::Object& object = scene_.objects()[i];
    if (object.model) AddItem(*object.model, object.scale, static_cast<int>(i), -1);
  }
  draw_robot_ = options_.draw_robot && scene_.robot().has_value() && scene_.robot()->visible;
  if (draw_robot_) {
    const std::vector<scene::RobotPart>& parts = scene_.robot()->parts;
    for (std::size_t i = 0; i < parts.size(); ++i) {
      if (parts[i].model) AddItem(*parts[i].model, parts[i].scale, -1, static_cast<int>(i));
    }
  }
  item_poses_.resize(items_.size(), Eigen::Isometry3d::Identity());
  order_.reserve(items_.size());
  draw_ground_ = scene_.ground().enabled;
  if (draw_ground_) {
    ground_vao_ = resources_->GroundQuad(0.5f * static_cast<float>(scene_.ground().size));
    BuildGroundProgram();
  }

  truth_ = options_.truth_depth || options_.truth_ids || options_.truth_objects;
  for (const scene::CameraSpec* camera : cameras_) {
    CameraSetup setup;
    const geometry::Intrinsics& K = camera->model.intrinsics();
    // The lens: distortion as calibrated, or the pinhole of K when switched off.
    const geometry::CameraModel model =
        options_.distortion ? camera->model : geometry::CameraModel(K);
    geometry::LensMap lens = geometry::MakeLensMap(model);
    setup.distorted = lens.kind != geometry::LensMap::Kind::kIdentity;
    setup.noise = options_.noise && camera->sensor.HasNoise();
    setup.blur = options_.motion_blur && camera->sensor.HasBlur();
    for (const geometry::SourceView& source : lens.views) {
      ViewSetup view;
      view.projection =
          geometry::GlProjectionFromIntrinsics(source.intrinsics, camera->clip, /*flip_rows=*/true);
      view.focal = std::max(source.intrinsics.fx(), source.intrinsics.fy());
      view.R_CV = source.R_CV;
      // The camera's +z in the view's optical frame, then in its OpenGL eye frame.
      view.depth_axis =
          (geometry::OpticalToGlEye() * source.R_CV.transpose() * Eigen::Vector3d::UnitZ())
              .cast<float>();
      setup.views.push_back(view);
    }
    if (setup.distorted || setup.noise || setup.blur || truth_) {
      if (!effect_programs_) effect_programs_ = std::make_unique<EffectPrograms>();
      setup.effects = std::make_unique<EffectTarget>(lens, samples_, setup.blur, truth_);
      // Build the programs now, not in the first frame.
      effect_programs_->GetFinal(!setup.distorted, setup.noise);
      if (truth_) effect_programs_->GetTruthRemap(!setup.distorted);
      targets_.push_back(nullptr);
    } else {
      targets_.push_back(std::make_unique<CameraTarget>(K.width(), K.height(), samples_, GL_RGBA));
    }
    setups_.push_back(std::move(setup));
  }
  for (Pending& pending : pending_) pending.X_WC.resize(cameras_.size());
  image_pools_.resize(cameras_.size());

  // Fixed state. The projection negates y (flip_rows), which mirrors the winding of every
  // triangle: front faces (counter-clockwise in the model) are clockwise in window
  // coordinates. Closed meshes have their back faces culled; open ones are two-sided, where
  // gl_FrontFacing says which side is seen.
  glFrontFace(GL_CW);
  glCullFace(GL_BACK);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_BLEND);
  glDisable(GL_DITHER);  // bit-identical pixels, whatever the device likes
  if (samples_ > 0) glEnable(GL_MULTISAMPLE);
  const Eigen::Vector3f background = scene_.background();
  glClearColor(background.x(), background.y(), background.z(), 1.0f);
  glClearDepth(1.0);
  glActiveTexture(GL_TEXTURE0);
  CheckGlError("MakeRenderer: setting up");

  description_ = fmt::format("OpenGL {}, {} (EGL: {})", version, renderer, context_.display_name());
  if (options_.msaa_samples > 0) {
    description_ += samples_ == options_.msaa_samples
                        ? fmt::format(", MSAA {}x", samples_)
                        : fmt::format(", MSAA {}x ({}x asked; the device's maximum)", samples_,
                                      options_.msaa_samples);
  }
}

GlRenderer::~GlRenderer() {
  try {
    context_.MakeCurrent();
  } catch (const Error&) {
    // The context is gone (or current on another thread): no GL call may be made, so the GL
    // objects' owners are leaked rather than destroyed (the context's end frees the objects).
    for (auto& target : targets_) static_cast<void>(target.release());
    for (CameraSetup& setup : setups_) static_cast<void>(setup.effects.release());
    static_cast<void>(effect_programs_.release());
    static_cast<void>(resources_.release());
    return;
  }
  for (Pending& pending : pending_) {
    if (pending.fence != nullptr) glDeleteSync(pending.fence);
  }
  targets_.clear();
  setups_.clear();
  effect_programs_.reset();
  resources_.reset();
  for (auto& [variant, program] : mesh_programs_) glDeleteProgram(program.program);
  if (ground_.program != 0) glDeleteProgram(ground_.program);
}

void GlRenderer::AddItem(const scene::Model& model, const Eigen::Vector3d& scale, int object,
                         int part) {
  DrawItem item;
  item.model = &resources_->Get(model);
  item.object = object;
  item.part = part;
  item.scale = scale;
  if (!model.bounds.isEmpty()) {
    item.center_model = model.bounds.center().cast<double>();
    item.radius_model = 0.5 * model.bounds.diagonal().cast<double>().cwiseProduct(scale).norm();
  }
  // Compile (and let the driver build) every program variant this model may use now, not in
  // the first frame.
  for (const GpuMesh& mesh : item.model->meshes) {
    const GpuMaterial& material = item.model->materials[mesh.material];
    const int base = (material.texture != 0 ? kTextured : 0) | (material.specular > 0 ? kShiny : 0);
    GetMeshProgram(base);
    GetMeshProgram(base | kPerVertex | (mesh.closed ? 0 : kTwoSided));
  }
  items_.push_back(item);
}

MeshProgram& GlRenderer::GetMeshProgram(int variant) {
  auto found = mesh_programs_.find(variant);
  if (found != mesh_programs_.end()) return found->second;
  const std::string defines = fmt::format(
      "#define TEXTURED {}\n#define SHINY {}\n#define PER_VERTEX {}\n#define TWO_SIDED {}\n",
      (variant & kTextured) ? 1 : 0, (variant & kShiny) ? 1 : 0, (variant & kPerVertex) ? 1 : 0,
      (variant & kTwoSided) ? 1 : 0);
  const std::string prefix = SourcePrefix(static_cast<int>(directional_lights_.size()),
                                          static_cast<int>(point_lights_.size()), defines) +
                             kLightingSource;
  MeshProgram p;
  p.program = BuildProgram(fmt::format("mesh variant {}", variant), prefix + kMeshVertexSource,
                           prefix + kMeshFragmentSource);
  p.mvp = Uniform(p.program, "u_mvp");
  p.mv = Uniform(p.program, "u_mv");
  p.normal = Uniform(p.program, "u_normal");
  p.base_color = Uniform(p.program, "u_base_color");
  p.specular = Uniform(p.program, "u_specular");
  p.shininess = Uniform(p.program, "u_shininess");
  p.lights.Find(p.program);
  glUseProgram(p.program);
  glUniform1i(Uniform(p.program, "u_texture"), 0);
  glUseProgram(0);
  CheckGlError("MakeRenderer: building a mesh program");
  return mesh_programs_.emplace(variant, p).first->second;
}

void GlRenderer::BuildGroundProgram() {
  const scene::Ground& ground = scene_.ground();
  const int pattern = ground.pattern == scene::Ground::Pattern::kPlain  ? 0
                      : ground.pattern == scene::Ground::Pattern::kGrid ? 1
                                                                        : 2;
  const std::string prefix = SourcePrefix(static_cast<int>(directional_lights_.size()),
                                          static_cast<int>(point_lights_.size()),
                                          fmt::format("#define PATTERN {}\n", pattern)) +
                             kLightingSource;
  ground_.program =
      BuildProgram("ground", prefix + kGroundVertexSource, prefix + kGroundFragmentSource);
  ground_.mvp = Uniform(ground_.program, "u_mvp");
  ground_.mv = Uniform(ground_.program, "u_mv");
  ground_.normal_eye = Uniform(ground_.program, "u_normal_eye");
  ground_.lights.Find(ground_.program);
  glUseProgram(ground_.program);
  glUniform1f(Uniform(ground_.program, "u_cell"), static_cast<float>(ground.cell));
  glUniform1f(Uniform(ground_.program, "u_line_fraction"),
              static_cast<float>(ground.line_width / ground.cell));
  glUniform3fv(Uniform(ground_.program, "u_color"), 1, ground.color.data());
  glUniform3fv(Uniform(ground_.program, "u_color2"), 1, ground.color2.data());
  glUseProgram(0);
  CheckGlError("MakeRenderer: building the ground program");
}

void GlRenderer::SetLights(const LightUniforms& uniforms, const Eigen::Isometry3d& X_EW) const {
  std::array<float, 3 * kMaxLights> directions{}, directional_colors{}, positions{};
  std::array<float, 4 * kMaxLights> point_colors{};
  for (std::size_t i = 0; i < directional_lights_.size(); ++i) {
    const scene::Light& light = *directional_lights_[i];
    // Towards the light, in the eye frame.
    const Eigen::Vector3f l = (-(X_EW.linear() * light.direction_W).normalized()).cast<float>();
    const Eigen::Vector3f c = light.color * light.intensity;
    std::copy(l.data(), l.data() + 3, directions.begin() + 3 * i);
    std::copy(c.data(), c.data() + 3, directional_colors.begin() + 3 * i);
  }
  for (std::size_t i = 0; i < point_lights_.size(); ++i) {
    const scene::Light& light = *point_lights_[i];
    const Eigen::Vector3f p = (X_EW * light.position_W).cast<float>();
    const Eigen::Vector3f c = light.color * light.intensity;
    std::copy(p.data(), p.data() + 3, positions.begin() + 3 * i);
    std::copy(c.data(), c.data() + 3, point_colors.begin() + 4 * i);
    point_colors[4 * i + 3] = static_cast<float>(light.attenuation);
  }
  glUniform3fv(uniforms.ambient, 1, ambient_.data());
  if (!directional_lights_.empty()) {
    const auto n = static_cast<GLsizei>(directional_lights_.size());
    glUniform3fv(uniforms.directional_direction, n, directions.data());
    glUniform3fv(uniforms.directional_color, n, directional_colors.data());
  }
  if (!point_lights_.empty()) {
    const auto n = static_cast<GLsizei>(point_lights_.size());
    glUniform3fv(uniforms.point_position, n, positions.data());
    glUniform4fv(uniforms.point_color, n, point_colors.data());
  }
}

void GlRenderer::UpdatePoses(const scene::SceneState& state) {
  std::optional<head::HeadFrames> frames;
  if (draw_robot_) frames = head::ForwardKinematics(scene_.robot()->head, state.joints);
  for (std::size_t i = 0; i < items_.size(); ++i) {
    const DrawItem& item = items_[i];
    if (item.object >= 0) {
      item_poses_[i] = scene_.ObjectPose(scene_.objects()[item.object], state);
    } else {
      const scene::RobotPart& part = scene_.robot()->parts[item.part];
      item_poses_[i] = LinkPose(*frames, part.link) * part.X_LinkPart;
    }
  }
}

Eigen::Isometry3d GlRenderer::EyeFromWorld(const geometry::Pose& X_WV) {
  // X_EW: OpenGL eye frame from world = OpticalToGlEye * X_WV^-1, in double.
  Eigen::Isometry3d X_EW = X_WV.inverse();
  X_EW.linear() = geometry::OpticalToGlEye() * X_EW.linear();
  X_EW.translation() = geometry::OpticalToGlEye() * X_EW.translation();
  return X_EW;
}

double GlRenderer::PixelsPerModelUnit(const DrawItem& item, double depth, double focal,
                                      double near) const {
  // Pixels per metre at the item's nearest point, for the size of its triangles on screen.
  const double nearest = depth - item.radius_model;
  return nearest > near ? focal * item.scale.maxCoeff() / nearest : 1e300;
}

uint32_t GlRenderer::ItemId(const DrawItem& item) const {
  return item.object >= 0 ? scene_.objects()[item.object].id : scene_.robot()->id;
}

void GlRenderer::SortItems(const Eigen::Isometry3d& X_EW) {
  // Objects front to back (the depth test then spares hidden fragments their shading).
  order_.clear();
  for (std::size_t i = 0; i < items_.size(); ++i) {
    const Eigen::Vector3d c =
        X_EW * (item_poses_[i] * items_[i].center_model.cwiseProduct(items_[i].scale));
    order_.emplace_back(-c.z(), static_cast<int>(i));
  }
  std::sort(order_.begin(), order_.end());
}

void GlRenderer::DrawScene(const ViewSetup& view, double near, const geometry::Pose& X_WV) {
  const Eigen::Matrix4d& P = view.projection;
  const double focal = view.focal;
  ++camera_pass_;
  const Eigen::Isometry3d X_EW = EyeFromWorld(X_WV);
  SortItems(X_EW);

  MeshProgram* program = nullptr;
  const GpuMaterial* material_set = nullptr;
  GLuint bound_texture = 0;
  bool culling = false;
  glDisable(GL_CULL_FACE);
  for (const auto& [depth, index] : order_) {
    const DrawItem& item = items_[index];
    Eigen::Affine3d MV = X_EW * item_poses_[index];
    MV.linear() = MV.linear() * item.scale.asDiagonal();
    const Eigen::Matrix4d mvp = P * MV.matrix();
    if (!item.model->bounds.isEmpty() && OutsideFrustum(mvp, item.model->bounds)) continue;
    const auto mvp_f = ToFloat<4>(mvp);
    const auto mv_f = ToFloat<4>(MV.matrix());
    const auto normal_f = ToFloat<3>(Eigen::Matrix3d(MV.linear().inverse().transpose()));
    const double px_per_model_unit = PixelsPerModelUnit(item, depth, focal, near);
    bool matrices_set = false;
    for (const GpuMesh& mesh : item.model->meshes) {
      const GpuMaterial& material = item.model->materials[mesh.material];
      const GpuLod& lod =
          mesh.levels[ChooseLod(mesh.errors, px_per_model_unit, options_.lod_max_error_px)];
      const bool shiny = material.specular > 0.0f;
      const bool per_vertex = (mesh.flat && !shiny && point_lights_.empty()) ||
                              lod.mean_edge * px_per_model_unit <= kPerVertexMaxEdgePx;
      const int variant = (material.texture != 0 ? kTextured : 0) | (shiny ? kShiny : 0) |
                          (per_vertex ? kPerVertex | (mesh.closed ? 0 : kTwoSided) : 0);
      MeshProgram& wanted = GetMeshProgram(variant);
      if (&wanted != program) {
        program = &wanted;
        glUseProgram(program->program);
        if (program->lights_pass != camera_pass_) {
          SetLights(program->lights, X_EW);
          program->lights_pass = camera_pass_;
        }
        matrices_set = false;
        material_set = nullptr;
      }
      if (!matrices_set) {
        glUniformMatrix4fv(program->mvp, 1, GL_FALSE, mvp_f.data());
        glUniformMatrix4fv(program->mv, 1, GL_FALSE, mv_f.data());
        glUniformMatrix3fv(program->normal, 1, GL_FALSE, normal_f.data());
        matrices_set = true;
      }
      if (&material != material_set) {
        glUniform4fv(program->base_color, 1, material.base_color.data());
        glUniform1f(program->specular, material.specular);
        glUniform1f(program->shininess, material.shininess);
        material_set = &material;
      }
      if (material.texture != 0 && material.texture != bound_texture) {
        glBindTexture(GL_TEXTURE_2D, material.texture);
        bound_texture = material.texture;
      }
      if (mesh.closed != culling) {
        culling = mesh.closed;
        culling ? glEnable(GL_CULL_FACE) : glDisable(GL_CULL_FACE);
      }
      glBindVertexArray(mesh.vao);
      glDrawElements(GL_TRIANGLES, lod.index_count, mesh.index_type,
                     reinterpret_cast<const void*>(lod.offset_bytes));
    }
  }
  if (culling) glDisable(GL_CULL_FACE);

  if (draw_ground_) {
    glUseProgram(ground_.program);
    SetLights(ground_.lights, X_EW);
    const auto mvp_f = ToFloat<4>(Eigen::Matrix4d(P * X_EW.matrix()));
    const auto mv_f = ToFloat<4>(X_EW.matrix());
    const Eigen::Vector3f normal_eye = (X_EW.linear() * Eigen::Vector3d::UnitZ()).cast<float>();
    glUniformMatrix4fv(ground_.mvp, 1, GL_FALSE, mvp_f.data());
    glUniformMatrix4fv(ground_.mv, 1, GL_FALSE, mv_f.data());
    glUniform3fv(ground_.normal_eye, 1, normal_eye.data());
    glBindVertexArray(ground_vao_);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  }
  glBindVertexArray(0);
}

void GlRenderer::DrawTruth(const ViewSetup& view, double near, const geometry::Pose& X_WV) {
  const Eigen::Matrix4d& P = view.projection;
  const Eigen::Isometry3d X_EW = EyeFromWorld(X_WV);
  SortItems(X_EW);
  const EffectPrograms::Truth& truth = effect_programs_->truth();
  glUseProgram(truth.program);
  glUniform3fv(truth.depth_axis, 1, view.depth_axis.data());
  bool culling = false;
  glDisable(GL_CULL_FACE);
  for (const auto& [depth, index] : order_) {
    const DrawItem& item = items_[index];
    Eigen::Affine3d MV = X_EW * item_poses_[index];
    MV.linear() = MV.linear() * item.scale.asDiagonal();
    const Eigen::Matrix4d mvp = P * MV.matrix();
    if (!item.model->bounds.isEmpty() && OutsideFrustum(mvp, item.model->bounds)) continue;
    const auto mvp_f = ToFloat<4>(mvp);
    const auto mv_f = ToFloat<4>(MV.matrix());
    glUniformMatrix4fv(truth.mvp, 1, GL_FALSE, mvp_f.data());
    glUniformMatrix4fv(truth.mv, 1, GL_FALSE, mv_f.data());
    glUniform1ui(truth.id, ItemId(item));
    const double px_per_model_unit = PixelsPerModelUnit(item, depth, view.focal, near);
    for (const GpuMesh& mesh : item.model->meshes) {
      // The same level of detail as the colour pass: the same silhouettes.
      const GpuLod& lod =
          mesh.levels[ChooseLod(mesh.errors, px_per_model_unit, options_.lod_max_error_px)];
      if (mesh.closed != culling) {
        culling = mesh.closed;
        culling ? glEnable(GL_CULL_FACE) : glDisable(GL_CULL_FACE);
      }
      glBindVertexArray(mesh.vao);
      glDrawElements(GL_TRIANGLES, lod.index_count, mesh.index_type,
                     reinterpret_cast<const void*>(lod.offset_bytes));
    }
  }
  if (culling) glDisable(GL_CULL_FACE);
  if (draw_ground_) {
    // The ground is a surface (it has depth) but not an object (id 0).
    const auto mvp_f = ToFloat<4>(Eigen::Matrix4d(P * X_EW.matrix()));
    const auto mv_f = ToFloat<4>(X_EW.matrix());
    glUniformMatrix4fv(truth.mvp, 1, GL_FALSE, mvp_f.data());
    glUniformMatrix4fv(truth.mv, 1, GL_FALSE, mv_f.data());
    glUniform1ui(truth.id, 0u);
    glBindVertexArray(ground_vao_);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  }
  glBindVertexArray(0);
}

void GlRenderer::Submit(const scene::SceneState& state, int64_t frame_index) {
  if (in_flight_ >= CameraTarget::kSlots) {
    throw Error(fmt::format(
        "Renderer::Submit: {} states are already in flight (frame indices {} and {}); Retrieve "
        "one first",
        in_flight_, pending_[oldest_].frame_index,
        pending_[(oldest_ + 1) % CameraTarget::kSlots].frame_index));
  }
  context_.MakeCurrent();
  const Clock::time_point start = Clock::now();
  const int slot = (oldest_ + in_flight_) % CameraTarget::kSlots;
  Pending& pending = pending_[slot];
  pending.state = state;
  pending.frame_index = frame_index;
  UpdatePoses(state);
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    pending.X_WC[i] = scene_.CameraPose(*cameras_[i], state);
  }
  const Clock::time_point posed = Clock::now();

  // Every camera first, then every readback: the rasteriser works on one camera while the
  // next is being submitted.
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    if (setups_[i].effects) continue;
    targets_[i]->BindForDrawing();
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    DrawScene(setups_[i].views[0], cameras_[i]->clip.near, pending.X_WC[i]);
  }
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    if (!setups_[i].effects) targets_[i]->StartReadback(slot);
  }
  const Clock::time_point drawn = Clock::now();
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    if (setups_[i].effects) {
      DrawEffects(static_cast<int>(i), state, frame_index, pending.X_WC[i], slot);
    }
  }
  pending.fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
  glFlush();
  ++in_flight_;
  const Clock::time_point end = Clock::now();
  stats_.scene_update_ms += Milliseconds(start, posed);
  stats_.draw_ms += Milliseconds(posed, drawn);
  stats_.effects_ms += Milliseconds(drawn, end);
  stats_.total_ms += Milliseconds(start, end);
}

bool GlRenderer::MovesDuringExposure(int camera, const scene::SceneState& state,
                                     const std::vector<scene::SceneState>& sub_states) const {
  const geometry::Pose X_WC = scene_.CameraPose(*cameras_[camera], state);
  const head::JointState& v = state.joint_velocities;
  const bool joints_move = v.pan != 0.0 || v.tilt != 0.0 || v.left != 0.0 || v.right != 0.0;
  if (joints_move && draw_robot_) return true;
  for (const scene::SceneState& sub : sub_states) {
    if (!scene_.CameraPose(*cameras_[camera], sub).isApprox(X_WC, 0.0)) return true;
    for (const DrawItem& item : items_) {
      if (item.object < 0) continue;
      const scene::Object& object = scene_.objects()[item.object];
      if (object.motion.IsStatic()) continue;
      if (!(object.motion.PoseAt(sub.time).matrix() == object.motion.PoseAt(state.time).matrix())) {
        return true;
      }
    }
  }
  return false;
}

void GlRenderer::DrawEffects(int camera, const scene::SceneState& state, int64_t frame_index,
                             const geometry::Pose& X_WC, int slot) {
  const CameraSetup& setup = setups_[camera];
  const EffectTarget& effects = *setup.effects;
  const scene::CameraSpec& spec = *cameras_[camera];
  const double near = spec.clip.near;
  const auto view_pose = [&](const geometry::Pose& X_WCk, int view) {
    geometry::Pose X_WV = X_WCk;
    X_WV.linear() = X_WCk.linear() * setup.views[view].R_CV;
    return X_WV;
  };

  // Motion blur: sub-frames at the midpoints of n equal slices of the exposure, centred on the
  // frame's time, the joints moving at their velocities; only when something moves.
  std::vector<scene::SceneState> sub_states;
  if (setup.blur) {
    const int n = spec.sensor.blur_samples;
    for (int k = 0; k < n; ++k) {
      const double dt = spec.sensor.exposure * ((k + 0.5) / n - 0.5);
      scene::SceneState sub = state;
      sub.time += dt;
      sub.joints.pan += state.joint_velocities.pan * dt;
      sub.joints.tilt += state.joint_velocities.tilt * dt;
      sub.joints.left += state.joint_velocities.left * dt;
      sub.joints.right += state.joint_velocities.right * dt;
      sub_states.push_back(sub);
    }
    if (!MovesDuringExposure(camera, state, sub_states)) sub_states.clear();
  }
  const int views = static_cast<int>(setup.views.size());
  if (sub_states.empty()) {
    for (int v = 0; v < views; ++v) {
      effects.BindViewForDrawing(v);
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      DrawScene(setup.views[v], near, view_pose(X_WC, v));
      effects.FinishView(v);
    }
  } else {
    effects.ClearAccumulation();
    const float weight = 1.0f / static_cast<float>(sub_states.size());
    for (const scene::SceneState& sub : sub_states) {
      UpdatePoses(sub);
      const geometry::Pose X_WCk = scene_.CameraPose(spec, sub);
      for (int v = 0; v < views; ++v) {
        effects.BindViewForDrawing(v);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        DrawScene(setup.views[v], near, view_pose(X_WCk, v));
        effects.FinishView(v);
        effects.Accumulate(*effect_programs_, v, weight);
      }
    }
    UpdatePoses(state);
  }
  if (effects.has_truth()) {
    for (int v = 0; v < views; ++v) {
      effects.BindTruthForDrawing(v);
      DrawTruth(setup.views[v], near, view_pose(X_WC, v));
    }
  }
  NoiseParams noise;
  noise.read_sigma_dn = static_cast<float>(spec.sensor.read_noise_dn);
  noise.gain_dn_per_e = static_cast<float>(spec.sensor.gain_dn_per_e);
  noise.key = NoiseKey(spec.sensor.seed, spec.name, frame_index);
  effects.Finish(*effect_programs_, !sub_states.empty(), setup.noise ? &noise : nullptr, slot);
}

std::shared_ptr<Image> GlRenderer::NewImage(int camera) {
  const geometry::Intrinsics& K = cameras_[camera]->model.intrinsics();
  std::vector<std::shared_ptr<Image>>& pool = image_pools_[camera];
  for (std::shared_ptr<Image>& image : pool) {
    // Only the pool holds it: the caller has let go of every frame that shared it.
    if (image.use_count() == 1) {
      std::atomic_thread_fence(std::memory_order_acquire);  // after the last reader's release
      return image;
    }
  }
  auto image = std::make_shared<Image>(K.width(), K.height(), PixelFormat::kRgb8);
  if (pool.size() < kPooledImagesPerCamera) pool.push_back(image);
  return image;
}

std::vector<Frame> GlRenderer::Retrieve() {
  if (in_flight_ == 0) {
    throw Error("Renderer::Retrieve: no state is in flight; Submit one first");
  }
  context_.MakeCurrent();
  const Clock::time_point start = Clock::now();
  const int slot = oldest_;
  Pending& pending = pending_[slot];
  GLenum status = GL_TIMEOUT_EXPIRED;
  while (status == GL_TIMEOUT_EXPIRED) {
    status = glClientWaitSync(pending.fence, GL_SYNC_FLUSH_COMMANDS_BIT,
                              GLuint64{1'000'000'000});  // 1 s, then again
  }
  glDeleteSync(pending.fence);
  pending.fence = nullptr;
  oldest_ = (oldest_ + 1) % CameraTarget::kSlots;
  --in_flight_;
  if (status == GL_WAIT_FAILED) {
    throw Error("Renderer::Retrieve: glClientWaitSync failed: " + GlErrorName(glGetError()));
  }

  std::vector<Frame> frames;
  frames.reserve(cameras_.size());
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    const scene::CameraSpec& camera = *cameras_[i];
    const CameraSetup& setup = setups_[i];
    std::shared_ptr<Image> image = NewImage(static_cast<int>(i));
    ImageMetadata& meta = image->metadata();
    meta.camera = camera.name;
    meta.time = pending.state.time;
    meta.frame_index = pending.frame_index;
    const Eigen::Matrix3d K = camera.model.intrinsics().Matrix();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) meta.K[3 * r + c] = K(r, c);
    }
    // The metadata describes the image as rendered: the lens's distortion, or a pinhole when
    // distortion is off (or the lens has none).
    if (setup.distorted) {
      meta.distortion_model = geometry::ToString(camera.model.distortion().model());
      meta.distortion = camera.model.distortion().coefficients();
    } else {
      meta.distortion_model = geometry::ToString(geometry::DistortionModel::kNone);
      meta.distortion.clear();
    }
    const Eigen::Matrix4d X_WC = pending.X_WC[i].matrix();
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) meta.X_WC[4 * r + c] = X_WC(r, c);
    }
    meta.has_joints = camera.mount != scene::CameraMount::kWorld;
    meta.joints = meta.has_joints
                      ? std::array<double, 4>{pending.state.joints.pan, pending.state.joints.tilt,
                                              pending.state.joints.left, pending.state.joints.right}
                      : std::array<double, 4>{};
    const std::size_t pixel_count =
        static_cast<std::size_t>(image->width()) * static_cast<std::size_t>(image->height());
    if (setup.effects) {
      const PixelBuffers& buffers = setup.effects->color_buffers();
      const auto* pixels = static_cast<const uint8_t*>(buffers.Map(slot));
      if (pixels == nullptr) {
        const GLenum error = glGetError();
        buffers.Unmap();
        throw Error("Renderer::Retrieve: glMapBufferRange failed: " + GlErrorName(error));
      }
      RgbaToRgb(pixels, image->data(), pixel_count);
      buffers.Unmap();
    } else {
      const CameraTarget& target = *targets_[i];
      const uint8_t* pixels = target.Map(slot);
      if (pixels == nullptr) {
        const GLenum error = glGetError();
        target.Unmap();
        throw Error("Renderer::Retrieve: glMapBufferRange failed: " + GlErrorName(error));
      }
      if (target.row_bytes() == static_cast<int>(image->stride())) {
        std::memcpy(image->data(), pixels, image->size_bytes());
      } else {
        RgbaToRgb(pixels, image->data(), pixel_count);
      }
      target.Unmap();
    }
    Frame frame{std::move(image), nullptr, nullptr, {}};
    if (truth_) FillTruth(static_cast<int>(i), pending, slot, &frame);
    frames.push_back(std::move(frame));
  }
  ++stats_.frames;
  const Clock::time_point end = Clock::now();
  stats_.readback_ms += Milliseconds(start, end);
  stats_.total_ms += Milliseconds(start, end);
  return frames;
}

void GlRenderer::FillTruth(int camera, const Pending& pending, int slot, Frame* frame) {
  const EffectTarget& effects = *setups_[camera].effects;
  const int width = frame->color->width();
  const int height = frame->color->height();
  const std::size_t bytes = static_cast<std::size_t>(width) * height * 4;
  const auto copy = [&](const PixelBuffers& buffers, PixelFormat format) {
    auto image = std::make_shared<Image>(width, height, format);
    image->metadata() = frame->color->metadata();
    const void* pixels = buffers.Map(slot);
    if (pixels == nullptr) {
      const GLenum error = glGetError();
      buffers.Unmap();
      throw Error("Renderer::Retrieve: glMapBufferRange failed (truth): " + GlErrorName(error));
    }
    std::memcpy(image->data(), pixels, bytes);
    buffers.Unmap();
    return image;
  };
  std::shared_ptr<Image> ids = copy(effects.id_buffers(), PixelFormat::kUint32);
  if (options_.truth_depth) frame->depth = copy(effects.depth_buffers(), PixelFormat::kFloat32);
  if (options_.truth_ids || options_.truth_objects) frame->ids = ids;
  if (!options_.truth_objects) return;

  // Poses at the frame's time, and boxes from the id image.
  const geometry::Pose X_CW = pending.X_WC[camera].inverse();
  std::map<uint32_t, std::size_t> index;  // id -> entry
  for (const scene::Object& object : scene_.objects()) {
    ObjectTruth truth;
    truth.id = object.id;
    truth.name = object.name;
    const geometry::Pose X_WO = scene_.ObjectPose(object, pending.state);
    truth.X_WO = X_WO.matrix();
    truth.X_CO = (X_CW * X_WO).matrix();
    index.emplace(truth.id, frame->objects.size());
    frame->objects.push_back(truth);
  }
  if (draw_robot_) {
    ObjectTruth truth;
    truth.id = scene_.robot()->id;
    truth.name = "robot";
    const geometry::Pose X_WB =
        head::ForwardKinematics(scene_.robot()->head, pending.state.joints).X_WB;
    truth.X_WO = X_WB.matrix();
    truth.X_CO = (X_CW * X_WB).matrix();
    index.emplace(truth.id, frame->objects.size());
    frame->objects.push_back(truth);
  }
  uint32_t last_id = 0;
  ObjectTruth* last = nullptr;
  for (int y = 0; y < height; ++y) {
    const auto* row = reinterpret_cast<const uint32_t*>(ids->row(y));
    for (int x = 0; x < width; ++x) {
      const uint32_t id = row[x];
      if (id == 0) continue;
      if (id != last_id || last == nullptr) {
        const auto found = index.find(id);
        if (found == index.end()) continue;  // cannot happen: every drawn id is listed
        last_id = id;
        last = &frame->objects[found->second];
      }
      if (last->pixels == 0) {
        last->x_min = last->x_max = x;
        last->y_min = last->y_max = y;
      }
      ++last->pixels;
      last->x_min = std::min(last->x_min, x);
      last->x_max = std::max(last->x_max, x);
      last->y_min = std::min(last->y_min, y);
      last->y_max = std::max(last->y_max, y);
    }
  }
}

std::vector<Frame> GlRenderer::Render(const scene::SceneState& state, int64_t frame_index) {
  if (in_flight_ != 0) {
    throw Error(fmt::format(
        "Renderer::Render: {} submitted state(s) not retrieved; Retrieve them before Render",
        in_flight_));
  }
  Submit(state, frame_index);
  return Retrieve();
}

}  // namespace

std::unique_ptr<Renderer> MakeGlRenderer(const scene::Scene& scene, const RendererOptions& options,
                                         const std::vector<std::string>& camera_names) {
  return std::make_unique<GlRenderer>(scene, options, camera_names);
}

}  // namespace saccade::render::gl
