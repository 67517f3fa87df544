#include "render/gl/internal_gl_renderer.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
#include <thread>
#include <utility>

#include "render/gl/internal_effect_shaders.h"
#include "render/gl/internal_gl_renderer_impl.h"
#include "render/gl/internal_lod.h"
#include "render/gl/internal_shaders.h"
#include "saccade/core/error.h"
#include "saccade/geometry/gl_projection.h"
#include "saccade/geometry/lens_map.h"

namespace saccade::render::gl {
namespace {

// The clip-space transform that maps a window rectangle (x, y, width, height) of a
// width x height view onto the whole of normalised device coordinates: its frustum is the
// rectangle's part of the view's.
Eigen::Matrix4d RegionFrustum(const std::array<int, 4>& r, int width, int height) {
  const double x0 = 2.0 * r[0] / width - 1.0, x1 = 2.0 * (r[0] + r[2]) / width - 1.0;
  const double y0 = 2.0 * r[1] / height - 1.0, y1 = 2.0 * (r[1] + r[3]) / height - 1.0;
  Eigen::Matrix4d S = Eigen::Matrix4d::Identity();
  S(0, 0) = 2.0 / std::max(x1 - x0, 1e-9);
  S(0, 3) = -(x0 + x1) / std::max(x1 - x0, 1e-9);
  S(1, 1) = 2.0 / std::max(y1 - y0, 1e-9);
  S(1, 3) = -(y0 + y1) / std::max(y1 - y0, 1e-9);
  return S;
}

// SplitMix64's finaliser (S. Vigna): a bijective 64-bit mix.
uint64_t Mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

}  // namespace

// The noise stream of one camera and frame: its seed, its name (FNV-1a) and the frame index.
uint32_t NoiseKey(uint64_t seed, const std::string& camera, int64_t frame_index) {
  uint64_t name = 0xcbf29ce484222325ull;
  for (const char c : camera) name = (name ^ static_cast<uint8_t>(c)) * 0x100000001b3ull;
  const uint64_t key = Mix64(Mix64(Mix64(seed) ^ name) ^ static_cast<uint64_t>(frame_index));
  return static_cast<uint32_t>(key ^ (key >> 32));
}

GlRenderer::GlRenderer(const scene::Scene& scene, const RendererOptions& options,
                       const std::vector<std::string>& camera_names)
    : scene_(scene), options_(options), camera_names_(camera_names) {
  for (const std::string& name : camera_names_) {
    const scene::CameraSpec* camera = scene_.FindCamera(name);
    SACCADE_ASSERT(camera != nullptr, "MakeRenderer checked the camera names");
    cameras_.push_back(camera);
  }
  SortLights();

  // Multisampling: as many samples as asked, or the device's maximum when it has fewer
  // (llvmpipe has 4); DeviceDescription says which.
  GLint max_samples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  samples_ = std::min(options_.msaa_samples, static_cast<int>(max_samples));

  const std::string version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  const std::string renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  ChooseDevicePaths(renderer);
  AddItems();

  truth_ = options_.truth_depth || options_.truth_ids || options_.truth_objects;
  BuildCameraSetups();
  for (Pending& pending : pending_) {
    pending.X_WC.resize(cameras_.size());
    pending.exposure_samples.assign(cameras_.size(), 1);
  }
  image_pools_.resize(cameras_.size());
  SetFixedState();

  description_ = fmt::format("OpenGL {}, {} (EGL: {})", version, renderer, context_.display_name());
  if (options_.msaa_samples > 0) {
    description_ += samples_ == options_.msaa_samples
                        ? fmt::format(", MSAA {}x", samples_)
                        : fmt::format(", MSAA {}x ({}x asked; the device's maximum)", samples_,
                                      options_.msaa_samples);
  }
}

void GlRenderer::SortLights() {
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
}

void GlRenderer::ChooseDevicePaths(const std::string& renderer) {
  // Software rasterisers implement anisotropic filtering as an elliptical weighted average
  // that is slow and, where texels map about 1:1 (or 2^k:1) to pixels, moves fine texture
  // detail by up to 0.08 px with the sub-pixel phase (measured on llvmpipe and softpipe):
  // trilinear filtering only there.
  const bool software = renderer.find("llvmpipe") != std::string::npos ||
                        renderer.find("softpipe") != std::string::npos;
  resources_ = std::make_unique<GpuResources>(/*anisotropic=*/!software);
  // On a software rasteriser a full-screen pass costs milliseconds an eye (a 1024 x 768 copy:
  // ~4 ms on llvmpipe), more than the same noise, and the lens remap, done on the CPU to the
  // pixels read back.
  noise_on_cpu_ = options_.noise_on_cpu.value_or(software);
  lens_on_cpu_ = options_.lens_on_cpu.value_or(software);
  turn_on_cpu_ = options_.turn_blur_on_cpu.value_or(software);
  batch_contexts_ = options_.batch_contexts != 0
                        ? options_.batch_contexts
                        : (software && std::thread::hardware_concurrency() >= 2 ? 2 : 1);
}

void GlRenderer::AddItems() {
  for (std::size_t i = 0; i < scene_.objects().size(); ++i) {
    const scene::Object& object = scene_.objects()[i];
    if (object.model) AddItem(*object.model, object.scale, static_cast<int>(i), -1);
  }
  draw_robot_ = options_.draw_robot && scene_.robot().has_value() && scene_.robot()->visible;
  turn_blur_max_error_px_ = options_.turn_blur ? options_.turn_blur_max_error_px : -1.0;
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
}

void GlRenderer::SetFixedState() {
  // The projection negates y (flip_rows), which mirrors the winding of every triangle: front
  // faces (counter-clockwise in the model) are clockwise in window coordinates. Closed meshes
  // have their back faces culled; open ones are two-sided, where gl_FrontFacing says which
  // side is seen.
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
}

// Builds the final pass's programs of `setup` now, not in its first frame: the map variant,
// and the mesh one where there is a lens.
void GlRenderer::PrebuildFinal(const CameraSetup& setup) {
  effect_programs_->GetFinal(!setup.distorted, setup.noise);
  if (setup.distorted) effect_programs_->GetFinal(false, setup.noise, /*mesh=*/true);
}

// How each camera renders, from options_'s effects: its source views, and its effect target
// (or its plain target when it needs no effect). `reuse`: the previous setups (SetEffects), whose
// effect targets are kept where the lens stays as it was (a switch of the noise or the blur
// remakes nothing: blur adds the accumulation array once, and keeps it); `reuse_distortion`:
// the distortion switch they were made with. Needs the context current.
void GlRenderer::BuildCameraSetups(std::vector<CameraSetup> reuse, bool reuse_distortion) {
  targets_.clear();
  setups_.clear();
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    const scene::CameraSpec* camera = cameras_[i];
    CameraSetup setup;
    if (i < reuse.size() && reuse[i].effects && reuse_distortion == options_.distortion) {
      setup = std::move(reuse[i]);
      SetChain(i, &setup);
      setup.blur = options_.motion_blur && camera->sensor.HasBlur();
      if (setup.blur) setup.effects->EnableBlur();
      if ((setup.distorted || setup.noise || setup.blur || setup.truth) &&
          (setup.effects->has_truth() || setup.effects->has_color_depth()) == setup.truth) {
        PrebuildFinal(setup);
        targets_.push_back(nullptr);
        setups_.push_back(std::move(setup));
        continue;
      }
      setup = CameraSetup();  // no effect left: the plain path
    }
    const geometry::Intrinsics& K = camera->model.intrinsics();
    // The lens: distortion as calibrated, or the pinhole of K when switched off.
    const geometry::CameraModel model =
        options_.distortion ? camera->model : geometry::CameraModel(K);
    geometry::LensMap lens = geometry::MakeLensMap(model);
    setup.distorted = lens.kind != geometry::LensMap::Kind::kIdentity;
    // The frames' camera model: the image as rendered (a pinhole of K without distortion).
    setup.rendered = std::make_shared<const geometry::CameraModel>(
        setup.distorted ? camera->model : geometry::CameraModel(K));
    SetChain(i, &setup);
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
    if (setup.distorted || setup.noise || setup.blur || setup.truth) {
      if (!effect_programs_) effect_programs_ = std::make_unique<EffectPrograms>();
      // The depth of field's depth alone: the colour pass's, where the CPU remaps the lens
      // (a software rasteriser) or there is nothing to remap (internal_color_depth.h).
      const bool identity = lens.kind == geometry::LensMap::Kind::kIdentity &&
                            lens.views[0].intrinsics.width() == lens.width &&
                            lens.views[0].intrinsics.height() == lens.height;
      const bool cpu_remap = lens.kind != geometry::LensMap::Kind::kIdentity && lens_on_cpu_;
      const bool color_depth = setup.truth && !truth_ && samples_ == 0 && lens.views.size() == 1 &&
                               (identity || cpu_remap);
      setup.effects = std::make_unique<EffectTarget>(
          lens, samples_, setup.blur, setup.truth && !color_depth, lens_on_cpu_, color_depth);
      if (color_depth) {
        setup.color_depth = MakeColorDepthMap(setup.views[0].projection, setup.views[0].R_CV,
                                              lens.views[0].intrinsics);
      }
      PrebuildFinal(setup);
      if (setup.truth && !color_depth) effect_programs_->GetTruthRemap(!setup.distorted);
      targets_.push_back(nullptr);
    } else {
      targets_.push_back(std::make_unique<CameraTarget>(K.width(), K.height(), samples_, GL_RGBA));
    }
    setups_.push_back(std::move(setup));
  }
}

void GlRenderer::SetChain(std::size_t i, CameraSetup* setup) const {
  const scene::CameraSpec& camera = *cameras_[i];
  setup->chain.reset();
  if ((options_.optics && camera.lens.Enabled()) ||
      (options_.color && camera.sensor.color.Enabled())) {
    setup->chain =
        std::make_unique<CameraChain>(camera, *setup->rendered, options_.optics, options_.color);
  }
  const bool noise = options_.noise && camera.sensor.HasNoise();
  // The lens's light comes before the sensor: the noise after vignetting and depth of field,
  // on the CPU, not fused with the readback or the final pass.
  setup->late_noise = noise && setup->chain && setup->chain->optics();
  setup->noise = noise && !setup->late_noise;
  setup->truth = truth_ || (setup->chain && setup->chain->depth_of_field());
}

void GlRenderer::SetEffects(const EffectSwitches& effects) {
  if (in_flight_ > 0) {
    throw Error(fmt::format(
        "Renderer::SetEffects: {} submitted state(s) not yet retrieved; Retrieve them first",
        in_flight_));
  }
  if (EffectSwitches::Of(options_) == effects) return;
  context_.MakeCurrent();
  const bool previous_distortion = options_.distortion;
  effects.ApplyTo(&options_);
  BuildCameraSetups(std::move(setups_), previous_distortion);
  glActiveTexture(GL_TEXTURE0);
  CheckGlError("Renderer::SetEffects");
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
    // The bounding sphere about the box's centre reaches the farthest vertex: for a sphere,
    // its radius, where the box's half diagonal is sqrt(3) times that (the moving regions of
    // motion blur, four times the area).
    item.center_model = model.bounds.center().cast<double>();
    double radius2 = 0.0;
    for (const scene::Mesh& mesh : model.meshes) {
      for (const Eigen::Vector3f& p : mesh.positions) {
        radius2 = std::max(
            radius2, (p.cast<double>() - item.center_model).cwiseProduct(scale).squaredNorm());
      }
    }
    item.radius_model = std::sqrt(radius2);
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
  SetLightColours(p.lights);
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
  SetLightColours(ground_.lights);
  glUniform1f(Uniform(ground_.program, "u_cell"), static_cast<float>(ground.cell));
  glUniform1f(Uniform(ground_.program, "u_line_fraction"),
              static_cast<float>(ground.line_width / ground.cell));
  glUniform3fv(Uniform(ground_.program, "u_color"), 1, ground.color.data());
  glUniform3fv(Uniform(ground_.program, "u_color2"), 1, ground.color2.data());
  glUseProgram(0);
  CheckGlError("MakeRenderer: building the ground program");
}

void GlRenderer::SetLightColours(const LightUniforms& uniforms) const {
  std::array<float, 3 * kMaxLights> directional_colors{};
  std::array<float, 4 * kMaxLights> point_colors{};
  for (std::size_t i = 0; i < directional_lights_.size(); ++i) {
    const scene::Light& light = *directional_lights_[i];
    const Eigen::Vector3f c = light.color * light.intensity;
    std::copy(c.data(), c.data() + 3, directional_colors.begin() + 3 * i);
  }
  for (std::size_t i = 0; i < point_lights_.size(); ++i) {
    const scene::Light& light = *point_lights_[i];
    const Eigen::Vector3f c = light.color * light.intensity;
    std::copy(c.data(), c.data() + 3, point_colors.begin() + 4 * i);
    point_colors[4 * i + 3] = static_cast<float>(light.attenuation);
  }
  glUniform3fv(uniforms.ambient, 1, ambient_.data());
  if (!directional_lights_.empty()) {
    glUniform3fv(uniforms.directional_color, static_cast<GLsizei>(directional_lights_.size()),
                 directional_colors.data());
  }
  if (!point_lights_.empty()) {
    glUniform4fv(uniforms.point_color, static_cast<GLsizei>(point_lights_.size()),
                 point_colors.data());
  }
}

void GlRenderer::SetLights(const LightUniforms& uniforms, const Eigen::Isometry3d& X_EW) const {
  std::array<float, 3 * kMaxLights> directions{}, positions{};
  for (std::size_t i = 0; i < directional_lights_.size(); ++i) {
    // Towards the light, in the eye frame.
    const Eigen::Vector3f l =
        (-(X_EW.linear() * directional_lights_[i]->direction_W).normalized()).cast<float>();
    std::copy(l.data(), l.data() + 3, directions.begin() + 3 * i);
  }
  for (std::size_t i = 0; i < point_lights_.size(); ++i) {
    const Eigen::Vector3f p = (X_EW * point_lights_[i]->position_W).cast<float>();
    std::copy(p.data(), p.data() + 3, positions.begin() + 3 * i);
  }
  if (!directional_lights_.empty()) {
    glUniform3fv(uniforms.directional_direction, static_cast<GLsizei>(directional_lights_.size()),
                 directions.data());
  }
  if (!point_lights_.empty()) {
    glUniform3fv(uniforms.point_position, static_cast<GLsizei>(point_lights_.size()),
                 positions.data());
  }
}

void GlRenderer::UpdatePoses(const scene::SceneState& state) {
  std::optional<LinkPoses> frames;
  if (draw_robot_) frames = RobotLinkPoses(*scene_.robot(), state.joints);
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

void GlRenderer::Submit(const scene::SceneState& state, int64_t frame_index) {
  if (in_flight_ >= CameraTarget::kSlots) {
    throw Error(fmt::format(
        "Renderer::Submit: {} states are already in flight (frame indices {} and {}); Retrieve "
        "one first",
        in_flight_, pending_[oldest_].frame_index,
        pending_[(oldest_ + 1) % CameraTarget::kSlots].frame_index));
  }
  scene_.ValidateControls(state, "Renderer::Submit");
  context_.MakeCurrent();
  const Clock::time_point start = Clock::now();
  const int slot = (oldest_ + in_flight_) % CameraTarget::kSlots;
  Pending& pending = pending_[slot];
  pending.state = state;
  pending.cpu_noise.assign(cameras_.size(), std::nullopt);  // DrawEffects sets them
  pending.cpu_lens.assign(cameras_.size(), false);
  pending.cpu_turn.assign(cameras_.size(), std::nullopt);
  pending.frame_index = frame_index;
  UpdatePoses(state);
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    pending.X_WC[i] = scene_.CameraPose(*cameras_[i], state);
    pending.exposure_samples[i] = 1;
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

geometry::Pose GlRenderer::ItemPose(const DrawItem& item, const scene::SceneState& state,
                                    const std::optional<LinkPoses>& frames) const {
  if (item.object >= 0) return scene_.ObjectPose(scene_.objects()[item.object], state);
  const scene::RobotPart& part = scene_.robot()->parts[item.part];
  return LinkPose(*frames, part.link) * part.X_LinkPart;
}

namespace {

// The angle of a rotation, in [0, pi].
double RotationAngle(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

// The pose of a camera's source view: the camera's (X_WC) turned by the view's R_CV.
geometry::Pose ViewPose(const ViewSetup& view, const geometry::Pose& X_WC) {
  geometry::Pose X_WV = X_WC;
  X_WV.linear() = X_WC.linear() * view.R_CV;
  return X_WV;
}

// `state` dt seconds later (earlier for dt < 0), the joints moving at their velocities.
scene::SceneState StateAfter(const scene::SceneState& state, double dt) {
  scene::SceneState sub = state;
  sub.time += dt;
  if (!state.joint_velocities.empty() && !sub.joints.empty()) {
    sub.joints.values() += state.joint_velocities.values() * dt;
  }
  return sub;
}

// A rectangle of a view's window: x0, y0, x1, y1 (pixels).
using Rect = std::array<double, 4>;

// The rectangle that holds the projections of `points` (eye frame) through P onto a view of
// k's size, as the rasteriser projects them; none when one lies behind the eye.
std::optional<Rect> ProjectedHull(const std::array<Eigen::Vector3d, 8>& points,
                                  const Eigen::Matrix4d& P, const geometry::Intrinsics& k) {
  Rect r{1e300, 1e300, -1e300, -1e300};
  for (const Eigen::Vector3d& p_E : points) {
    const Eigen::Vector4d clip = P * Eigen::Vector4d(p_E.x(), p_E.y(), p_E.z(), 1.0);
    if (clip.w() <= 1e-9) return std::nullopt;
    const double x = 0.5 * (clip.x() / clip.w() + 1.0) * k.width();
    const double y = 0.5 * (clip.y() / clip.w() + 1.0) * k.height();
    r = {std::min(r[0], x), std::min(r[1], y), std::max(r[2], x), std::max(r[3], y)};
  }
  return r;
}

// The rectangle of a view (eye frame X_EW, projection P, k's size) that holds the image of an
// item at X_WO, or none. Its image lies within two hulls: of the corners of the cube around
// its bounding sphere, and of the corners of its model's box (far tighter for a flat picture,
// whose sphere reaches past it on every side). Their intersection holds it while every corner
// of one of them lies in front of the eye; none when neither does.
std::optional<Rect> ItemImageRect(const DrawItem& item, const geometry::Pose& X_WO,
                                  const Eigen::Isometry3d& X_EW, const Eigen::Matrix4d& P,
                                  const geometry::Intrinsics& k) {
  const double r = item.radius_model;
  const Eigen::Vector3d c_E = X_EW * (X_WO * item.center_model.cwiseProduct(item.scale));
  std::array<Eigen::Vector3d, 8> corners;
  for (int corner = 0; corner < 8; ++corner) {
    corners[corner] =
        c_E + Eigen::Vector3d((corner & 1) ? r : -r, (corner & 2) ? r : -r, (corner & 4) ? r : -r);
  }
  std::optional<Rect> rect = ProjectedHull(corners, P, k);
  if (item.model != nullptr && !item.model->bounds.isEmpty()) {
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d c =
          item.model->bounds.corner(static_cast<Eigen::AlignedBox3f::CornerType>(corner))
              .cast<double>();
      corners[corner] = X_EW * (X_WO * c.cwiseProduct(item.scale));
    }
    if (const std::optional<Rect> box = ProjectedHull(corners, P, k)) {
      rect = rect ? Rect{std::max((*rect)[0], (*box)[0]), std::max((*rect)[1], (*box)[1]),
                         std::min((*rect)[2], (*box)[2]), std::min((*rect)[3], (*box)[3])}
                  : *box;
    }
  }
  return rect;
}

// The window rectangle (x, y, width, height) of a view (eye frame X_EW, projection P, k's
// size) that holds the images of the `moving` items (each at its pose), with a margin; empty
// when there are none; none when one reaches behind the eye.
std::optional<std::array<int, 4>> MovingRegion(
    const std::vector<std::pair<const DrawItem*, geometry::Pose>>& moving,
    const Eigen::Isometry3d& X_EW, const Eigen::Matrix4d& P, const geometry::Intrinsics& k) {
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const auto& [item, X_WO] : moving) {
    const std::optional<Rect> rect = ItemImageRect(*item, X_WO, X_EW, P, k);
    if (!rect) return std::nullopt;
    x0 = std::min(x0, (*rect)[0]);
    y0 = std::min(y0, (*rect)[1]);
    x1 = std::max(x1, (*rect)[2]);
    y1 = std::max(y1, (*rect)[3]);
  }
  // Margin: two pixels for rasterisation and multisampling, one for the camera's own motion
  // (under a pixel over the exposure); empty when nothing moves in the view.
  constexpr double kMarginPx = 3.0;
  const int left = static_cast<int>(std::clamp(std::floor(x0 - kMarginPx), 0.0, double(k.width())));
  const int right = static_cast<int>(std::clamp(std::ceil(x1 + kMarginPx), 0.0, double(k.width())));
  const int bottom =
      static_cast<int>(std::clamp(std::floor(y0 - kMarginPx), 0.0, double(k.height())));
  const int top = static_cast<int>(std::clamp(std::ceil(y1 + kMarginPx), 0.0, double(k.height())));
  return std::array<int, 4>{left, bottom, std::max(0, right - left), std::max(0, top - bottom)};
}

}  // namespace

// The pinhole of a camera's K as ImageMotionPx bounds image motion through it.
struct GlRenderer::MotionGains {
  MotionGains(const geometry::Intrinsics& k, double near_clip)
      : near(near_clip),
        left(k.cx() / k.fx()),
        right((k.width() - k.cx()) / k.fx()),
        top(k.cy() / k.fy()),
        bottom((k.height() - k.cy()) / k.fy()) {
    const double tx = std::max(left, right), ty = std::max(top, bottom);
    f = std::max(k.fx(), k.fy());
    // The camera turning by an angle moves a ray at angle a from its axis by f (1 + tan^2 a)
    // pixels per radian, most at the image's corners; a point shifting by d at depth z moves
    // by at most f (1 + tan a) d / z pixels.
    turn_gain = f * (1.0 + tx * tx + ty * ty);
    shift_gain = f * (1.0 + std::max(tx, ty));
    corner = std::hypot(tx, ty);
  }

  // What a homography of the turn cannot follow: the parallax of a shift d (camera frame)
  // moves a point at depth z and normalised image position q by (q d_z - d_xy) / (z - d_z),
  // at most (|d_xy| + |q|max |d_z|) / (z - |d_z|): a sideways shift (the eyes swung by the
  // neck's pan) is not charged the corners' gain, which only the shift along the axis has.
  double ParallaxPx(const Eigen::Vector3d& d_C, double depth) const {
    return f * (d_C.head<2>().norm() + corner * std::abs(d_C.z())) /
           std::max(depth - std::abs(d_C.z()), near);
  }

  // Whether a sphere (centre in the camera frame, radius) lies wholly outside the view.
  bool Outside(const Eigen::Vector3d& c, double r) const {
    const auto beyond = [&](double lateral, double tan_half) {  // past one side plane
      return (lateral - tan_half * c.z()) / std::sqrt(1.0 + tan_half * tan_half) > r;
    };
    return c.z() + r < near || beyond(c.x(), right) || beyond(-c.x(), left) ||
           beyond(c.y(), bottom) || beyond(-c.y(), top);
  }

  double near;                      // the near clip plane
  double left, right, top, bottom;  // tangents of the view's half-angles from its axis
  double f = 0.0;                   // the larger focal length (pixels)
  double turn_gain = 0.0, shift_gain = 0.0;
  double corner = 0.0;  // the tangent of the angle to the farthest corner
};

// A camera's motion between two states (ImageMotionPx).
struct GlRenderer::CameraMotion {
  geometry::Pose X_WC0, X_WC1, X_CW0, X_CW1;
  Eigen::Vector3d shift;  // X_WC1's origin less X_WC0's (world frame)
  double turn = 0.0;      // the angle between their orientations (radians)
};

double GlRenderer::ImageMotionPx(int camera, const scene::SceneState& s0,
                                 const scene::SceneState& s1, double* camera_px,
                                 std::vector<double>* item_px, double* turn_only_px) const {
  const scene::CameraSpec& spec = *cameras_[camera];
  const double near = spec.clip.near;
  const MotionGains gains(spec.model.intrinsics(), near);
  CameraMotion motion;
  motion.X_WC0 = scene_.CameraPose(spec, s0);
  motion.X_WC1 = scene_.CameraPose(spec, s1);
  // The camera's turn moves everything alike; its shift moves the ground most nearby (at
  // its height) and each item by its own depth, as do the items' own motions.
  motion.turn = RotationAngle(motion.X_WC0.linear().transpose() * motion.X_WC1.linear());
  motion.shift = motion.X_WC1.translation() - motion.X_WC0.translation();
  const double ground_depth = std::max(std::abs(motion.X_WC0.translation().z()), near);
  const double ground_shift_px = gains.shift_gain * motion.shift.norm() / ground_depth;
  double px = gains.turn_gain * motion.turn + ground_shift_px;
  if (camera_px != nullptr) *camera_px = px;
  double off_turn =
      gains.ParallaxPx(motion.X_WC0.linear().transpose() * motion.shift, ground_depth);
  std::optional<LinkPoses> frames0, frames1;
  if (draw_robot_) {
    frames0 = RobotLinkPoses(*scene_.robot(), s0.joints);
    frames1 = RobotLinkPoses(*scene_.robot(), s1.joints);
  }
  motion.X_CW0 = motion.X_WC0.inverse();
  motion.X_CW1 = motion.X_WC1.inverse();
  if (item_px != nullptr) item_px->assign(items_.size(), 0.0);
  for (std::size_t i = 0; i < items_.size(); ++i) {
    const DrawItem& item = items_[i];
    const std::optional<double> item_motion =
        ItemMotionPx(item, ItemPose(item, s0, frames0), ItemPose(item, s1, frames1), gains, motion,
                     setups_[camera].views, turn_only_px != nullptr ? &off_turn : nullptr);
    if (!item_motion) continue;
    if (item_px != nullptr) (*item_px)[i] = *item_motion;
    px = std::max(px, *item_motion);
  }
  if (turn_only_px != nullptr) *turn_only_px = off_turn;
  return px;
}

std::optional<double> GlRenderer::ItemMotionPx(const DrawItem& item, const geometry::Pose& X_WO0,
                                               const geometry::Pose& X_WO1,
                                               const MotionGains& gains, const CameraMotion& camera,
                                               const std::vector<ViewSetup>& views,
                                               double* off_turn) const {
  const Eigen::Vector3d centre = item.center_model.cwiseProduct(item.scale);
  const Eigen::Vector3d c0 = X_WO0 * centre, c1 = X_WO1 * centre;  // world
  // Out of view at both ends of the exposure (a robot part behind the eye, say): its motion
  // is not seen.
  if (gains.Outside(camera.X_CW0 * c0, item.radius_model) &&
      gains.Outside(camera.X_CW1 * c1, item.radius_model)) {
    return std::nullopt;
  }
  // A point of the item's bounding sphere moves by its centre's motion plus at most its
  // turn times the radius, seen at the sphere's nearest depth. Two bounds, the smaller
  // kept: in the camera's frame (an item that moves with the camera, a part of the head,
  // hardly moves), and in the world's, the camera's turn apart (a still item does not).
  const double r = item.radius_model;
  const double depth = std::max((camera.X_CW0 * c0).z() - r, gains.near);
  const double relative_turn = RotationAngle((camera.X_CW0.linear() * X_WO0.linear()).transpose() *
                                             (camera.X_CW1.linear() * X_WO1.linear()));
  const double in_camera = gains.shift_gain *
                           ((camera.X_CW1 * c1 - camera.X_CW0 * c0).norm() + relative_turn * r) /
                           depth;
  const double item_turn = RotationAngle(X_WO0.linear().transpose() * X_WO1.linear());
  const double in_world =
      gains.turn_gain * camera.turn +
      gains.shift_gain * (((c1 - c0) - camera.shift).norm() + item_turn * r) / depth;
  const double item_motion = std::min(in_camera, in_world);
  if (off_turn == nullptr) return item_motion;  // turn blur off: the bound below is not needed
  // Where the item is at s1 in the camera, against where the camera's turn alone would put
  // it: a still item is off by the camera's shift (parallax), a part that moves with the
  // camera by the turn itself, a moving item by its motion. An item whose box is out of the
  // (single) view at both ends is not seen: the head's body behind the eyes, whose bounding
  // sphere reaches past them.
  if (item.model != nullptr && !item.model->bounds.isEmpty() && views.size() == 1) {
    const auto box_outside = [&](const geometry::Pose& X_WC, const geometry::Pose& X_WO) {
      Eigen::Affine3d MV = EyeFromWorld(ViewPose(views[0], X_WC)) * X_WO;
      MV.linear() = MV.linear() * item.scale.asDiagonal();
      return OutsideFrustum(views[0].projection * MV.matrix(), item.model->bounds);
    };
    if (box_outside(camera.X_WC0, X_WO0) && box_outside(camera.X_WC1, X_WO1)) return item_motion;
  }
  const Eigen::Vector3d p0 = camera.X_CW0 * c0, p1 = camera.X_CW1 * c1;
  const Eigen::Vector3d turned = camera.X_CW1.linear() * camera.X_WC0.linear() * p0;
  *off_turn = std::max(*off_turn, gains.ParallaxPx(p1 - turned, depth) +
                                      gains.f * (1.0 + gains.corner) * item_turn * r / depth);
  return item_motion;
}

GlRenderer::MovingPoses GlRenderer::MovingItems(const std::vector<scene::SceneState>& subs,
                                                const std::vector<double>& item_px) const {
  std::vector<std::optional<LinkPoses>> frames(subs.size());
  if (draw_robot_) {
    for (std::size_t k = 0; k < subs.size(); ++k) {
      frames[k] = RobotLinkPoses(*scene_.robot(), subs[k].joints);
    }
  }
  MovingPoses moving;
  for (std::size_t i = 0; i < items_.size(); ++i) {
    // Under a pixel over the exposure, an item is as still as the camera (no ghost step).
    if (item_px[i] < 1.0) continue;
    const DrawItem& item = items_[i];
    std::vector<geometry::Pose> poses;
    for (std::size_t k = 0; k < subs.size(); ++k) {
      poses.push_back(ItemPose(item, subs[k], frames[k]));
    }
    const bool moves = std::any_of(poses.begin(), poses.end(), [&](const geometry::Pose& X) {
      return X.matrix() != poses.front().matrix();
    });
    if (!moves) continue;
    for (const geometry::Pose& X_WO : poses) moving.emplace_back(&item, X_WO);
  }
  return moving;
}

std::vector<std::optional<GlRenderer::Region>> GlRenderer::MovingRegions(
    int camera, const std::vector<scene::SceneState>& subs, std::size_t whole,
    const std::vector<double>& item_px) const {
  const CameraSetup& setup = setups_[camera];
  const int views = static_cast<int>(setup.views.size());
  const geometry::Pose X_WC = scene_.CameraPose(*cameras_[camera], subs[whole]);
  const MovingPoses moving = MovingItems(subs, item_px);
  std::vector<std::optional<Region>> regions(views);
  for (int v = 0; v < views; ++v) {
    regions[v] = MovingRegion(moving, EyeFromWorld(ViewPose(setup.views[v], X_WC)),
                              setup.views[v].projection, setup.effects->lens().views[v].intrinsics);
  }
  return regions;
}

GlRenderer::ExposurePlan GlRenderer::PlanExposure(int camera,
                                                  const scene::SceneState& state) const {
  const CameraSetup& setup = setups_[camera];
  const scene::CameraSpec& spec = *cameras_[camera];
  ExposurePlan plan;
  // Motion blur: sub-frames at the midpoints of n equal slices of the exposure, centred on the
  // frame's time, the joints moving at their velocities. n is what the image motion over the
  // exposure needs for no step between sub-frames to exceed a pixel (1 when nothing moves:
  // one instant), up to the scene's blur_samples.
  if (setup.blur) {
    const double exposure = scene_.ControlsOf(spec, state).exposure_s;  // the commanded one
    const double motion_px =
        ImageMotionPx(camera, StateAfter(state, -0.5 * exposure), StateAfter(state, 0.5 * exposure),
                      &plan.camera_px, &plan.item_px,
                      turn_blur_max_error_px_ >= 0.0 ? &plan.turn_only_px : nullptr);
    const int n = static_cast<int>(
        std::clamp(std::ceil(motion_px), 1.0, static_cast<double>(spec.sensor.blur_samples)));
    plan.samples = n;
    if (n > 1) {
      for (int k = 0; k < n; ++k) {
        plan.sub_states.push_back(StateAfter(state, exposure * ((k + 0.5) / n - 0.5)));
      }
    }
  }
  // A turning camera (a saccade): the n sub-frames fall into m stretches of the exposure, and
  // each stretch's are the instant drawn at its middle seen through the turn's homographies:
  // m scene passes and m passes of fetches instead of n scene passes. What the turn cannot
  // explain -- the parallax of the camera's shift, items moving in the world -- accrues
  // turn_only_px over the whole exposure, so a sub-frame departs from drawing it by at most
  // turn_only_px times its distance from its stretch's middle, a fraction of the exposure
  // (at most half a stretch): m is the fewest stretches that keep that within
  // turn_blur_max_error_px, and the turn is used when m < n (an eye's saccade: 1; the neck's
  // pan, whose turn swings the eyes, or a ball rolling by: 2 or 3).
  const int count = static_cast<int>(plan.sub_states.size());
  if (count > 1 && setup.views.size() == 1 && plan.camera_px >= 1.0 &&
      count <= kMaxTurnBlurSamples && turn_blur_max_error_px_ >= 0.0) {
    for (int m = 1; m < count && plan.stretches == 0; ++m) {
      const int longest = (count + m - 1) / m;  // sub-frames in the longest stretch
      if (0.5 * longest * plan.turn_only_px / count <= turn_blur_max_error_px_) plan.stretches = m;
    }
  }
  return plan;
}

void GlRenderer::DrawEffects(int camera, const scene::SceneState& state, int64_t frame_index,
                             const geometry::Pose& X_WC, int slot) {
  const CameraSetup& setup = setups_[camera];
  const EffectTarget& effects = *setup.effects;
  const double near = cameras_[camera]->clip.near;
  const ExposurePlan plan = PlanExposure(camera, state);
  pending_[slot].exposure_samples[camera] = plan.samples;
  // Up to kMaxTurnStretches stretches are drawn into layers of their own and the final pass
  // fetches every sub-frame through its homography (TurnSamples): no accumulation pass. More
  // stretches accumulate each one's sub-frames (TurnBlur) and the final pass reads the sum.
  TurnSamples turn;
  const bool fused = plan.stretches > 0 && plan.stretches <= effects.turn_stretches();
  bool accumulated = false;  // the final pass reads the accumulation
  if (plan.stretches > 0) {
    DrawTurnStretches(camera, state, plan, fused ? &turn : nullptr, slot);
    accumulated = !fused;
  } else if (plan.sub_states.empty()) {
    for (int v = 0; v < static_cast<int>(setup.views.size()); ++v) {
      effects.BindViewForDrawing(v);
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      DrawScene(setup.views[v], near, ViewPose(setup.views[v], X_WC));
      effects.FinishView(v);
    }
    if (effects.has_color_depth()) effects.ReadColorDepth(slot);
  } else {
    accumulated = DrawSubFrames(camera, state, plan, slot);
  }
  if (effects.has_truth()) {
    for (int v = 0; v < static_cast<int>(setup.views.size()); ++v) {
      effects.BindTruthForDrawing(v);
      DrawTruth(setup.views[v], near, ViewPose(setup.views[v], X_WC));
    }
  }
  FinishEffects(camera, frame_index, slot, accumulated, fused ? &turn : nullptr, plan.stretches);
}

void GlRenderer::DrawTurnStretches(int camera, const scene::SceneState& state,
                                   const ExposurePlan& plan, TurnSamples* turn, int slot) {
  const CameraSetup& setup = setups_[camera];
  const EffectTarget& effects = *setup.effects;
  const scene::CameraSpec& spec = *cameras_[camera];
  const bool fused = turn != nullptr;
  const int count = static_cast<int>(plan.sub_states.size()), stretches = plan.stretches;
  const Eigen::Matrix3d K = effects.lens().views[0].intrinsics.Matrix();
  const Eigen::Matrix3d K_inv = K.inverse();
  const double exposure = scene_.ControlsOf(spec, state).exposure_s;
  std::vector<Eigen::Matrix3f> homographies;
  for (int g = 0; g < stretches; ++g) {
    const int first = g * count / stretches, end = (g + 1) * count / stretches;
    const scene::SceneState middle =
        StateAfter(state, exposure * (0.5 * (first + end) / count - 0.5));
    UpdatePoses(middle);
    const geometry::Pose X_WV = ViewPose(setup.views[0], scene_.CameraPose(spec, middle));
    if (fused) {
      effects.BindStretchForDrawing(g);
    } else {
      effects.BindViewForDrawing(0);
    }
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    DrawScene(setup.views[0], spec.clip.near, X_WV);
    if (fused) {
      effects.FinishStretch(g);
    } else {
      effects.FinishView(0);
    }
    if (g == stretches / 2 && effects.has_color_depth()) effects.ReadColorDepth(slot);
    homographies.clear();
    for (int k = first; k < end; ++k) {
      // A pixel of sub-frame k: its ray in view k, in the world, in the drawn view, its pixel.
      const Eigen::Matrix3d R_VVk =
          X_WV.linear().transpose() *
          ViewPose(setup.views[0], scene_.CameraPose(spec, plan.sub_states[k])).linear();
      homographies.push_back((K * R_VVk * K_inv).cast<float>());
    }
    if (fused) {
      turn->homographies.insert(turn->homographies.end(), homographies.begin(), homographies.end());
      turn->layers.insert(turn->layers.end(), homographies.size(), static_cast<float>(g));
      continue;
    }
    effects.TurnBlur(
        *effect_programs_, 0, homographies, 1.0f / static_cast<float>(count),
        g == 0 ? EffectTarget::Accumulation::kReplace : EffectTarget::Accumulation::kAdd);
  }
  UpdatePoses(state);
}

bool GlRenderer::DrawSubFrames(int camera, const scene::SceneState& state, const ExposurePlan& plan,
                               int slot) {
  const CameraSetup& setup = setups_[camera];
  const EffectTarget& effects = *setup.effects;
  const scene::CameraSpec& spec = *cameras_[camera];
  const double near = spec.clip.near;
  const int views = static_cast<int>(setup.views.size());
  const std::vector<scene::SceneState>& sub_states = plan.sub_states;
  // The camera still (under a pixel over the exposure: as for blur itself, a sub-pixel step
  // is no ghost), the sub-frame nearest the frame's time is drawn whole and the others only
  // where they can differ from it (MovingRegions: the moving items' sweep), the whole one
  // standing for all of them elsewhere: a still head watching a small moving ball redraws
  // the ball's box, not the image, per sub-frame. A moving camera redraws everything.
  const std::size_t count = sub_states.size(), whole = count / 2;
  const bool still = plan.camera_px < 1.0;
  std::vector<std::optional<Region>> regions(views);
  if (still) regions = MovingRegions(camera, sub_states, whole, plan.item_px);
  const auto scissor = [](const Region& r) {
    glEnable(GL_SCISSOR_TEST);
    glScissor(r[0], r[1], r[2], r[3]);
  };
  const float weight = 1.0f / static_cast<float>(count);
  using Mode = EffectTarget::Accumulation;
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t k = i == 0 ? whole : (i <= whole ? i - 1 : i);  // whole one first
    UpdatePoses(sub_states[k]);
    const geometry::Pose X_WCk = scene_.CameraPose(spec, sub_states[k]);
    for (int v = 0; v < views; ++v) {
      const std::optional<Region>& region = regions[v];
      const bool part = i > 0 && region;
      if (part) scissor(*region);
      effects.BindViewForDrawing(v);
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      if (part) {
        // Only the items that reach the region: the frustum of its rectangle.
        const geometry::Intrinsics& size = effects.lens().views[v].intrinsics;
        const Eigen::Matrix4d cull = RegionFrustum(*region, size.width(), size.height());
        DrawScene(setup.views[v], near, ViewPose(setup.views[v], X_WCk), &cull);
      } else {
        DrawScene(setup.views[v], near, ViewPose(setup.views[v], X_WCk));
      }
      effects.FinishView(v);
      if (i == 0 && effects.has_color_depth()) effects.ReadColorDepth(slot);  // the middle's
      if (region) scissor(*region);
      effects.Accumulate(*effect_programs_, v, weight, i == 0 ? Mode::kReplace : Mode::kAdd);
      glDisable(GL_SCISSOR_TEST);
    }
  }
  // Still camera: the blurred regions go back into the source views, which hold the whole
  // sub-frame elsewhere, and the final pass reads those (8 bits, as without blur).
  if (still) {
    for (int v = 0; v < views; ++v) {
      if (regions[v]) scissor(*regions[v]);
      effects.WriteBack(*effect_programs_, v);
      glDisable(GL_SCISSOR_TEST);
    }
  }
  UpdatePoses(state);
  return !still;
}

void GlRenderer::FinishEffects(int camera, int64_t frame_index, int slot, bool accumulated,
                               TurnSamples* turn, int stretches) {
  const CameraSetup& setup = setups_[camera];
  const EffectTarget& effects = *setup.effects;
  const scene::CameraSpec& spec = *cameras_[camera];
  const bool fused = turn != nullptr;
  NoiseParams noise;
  noise.read_sigma_dn = static_cast<float>(spec.sensor.read_noise_dn);
  noise.gain_dn_per_e = static_cast<float>(spec.sensor.gain_dn_per_e);
  noise.key = NoiseKey(spec.sensor.seed, spec.name, frame_index);
  // Nothing for the final pass to do but copy the source view and add noise: skipped, the
  // noise added to the pixels read back (Retrieve) when it goes on the CPU. The same with a
  // lens remapped on the CPU, which takes the noise with it.
  const bool copy_only = effects.can_read_source() && !accumulated && !fused;
  const bool cpu_lens = effects.cpu_lens() != nullptr;
  // A turn into stretch layers of a pinhole camera, no truth: its fetches on the CPU, with
  // the noise (RendererOptions::turn_blur_on_cpu).
  if (fused && turn_on_cpu_ && !effects.has_truth() &&
      effects.lens().kind == geometry::LensMap::Kind::kIdentity) {
    CpuTurn cpu_turn;
    cpu_turn.homographies = std::move(turn->homographies);
    for (const float layer : turn->layers) cpu_turn.layers.push_back(static_cast<int>(layer));
    cpu_turn.stretches = stretches;
    if (setup.noise) pending_[slot].cpu_noise[camera] = noise;
    pending_[slot].cpu_turn[camera] = std::move(cpu_turn);
    effects.ReadStretches(slot, stretches);
    return;
  }
  if (copy_only && (!setup.noise || noise_on_cpu_ || cpu_lens)) {
    if (setup.noise) pending_[slot].cpu_noise[camera] = noise;
    pending_[slot].cpu_lens[camera] = cpu_lens;
    effects.ReadSource(slot);
    effects.FinishTruth(*effect_programs_, slot);
    return;
  }
  effects.Finish(*effect_programs_, accumulated, setup.noise ? &noise : nullptr, slot, turn);
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

std::unique_ptr<Renderer> MakeGlRenderer(const scene::Scene& scene, const RendererOptions& options,
                                         const std::vector<std::string>& camera_names) {
  return std::make_unique<GlRenderer>(scene, options, camera_names);
}

}  // namespace saccade::render::gl
