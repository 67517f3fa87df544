#pragma once
// Rendering a scene through its calibrated cameras, headless. The public interface hides the
// backend (OpenGL 3.3 core through EGL, surfaceless: Mesa llvmpipe without a GPU, the vendor
// driver with one); no GL or EGL header appears here.
//
// Each camera renders through its own framebuffer with the projection built from its K
// (geometry/gl_projection.h), at its exact size; the rows are flipped on the GPU so that the
// frames come back with row 0 at the top; pixels come back through pixel buffer objects,
// asynchronously and double buffered.
//
// Effects (seed section 4.3), each switchable: a camera with lens distortion is drawn as one
// wider pinhole view, or as cube faces for lenses beyond 120 degrees, and remapped per pixel
// (geometry/lens_map.h) so that points land where cv::projectPoints /
// cv::fisheye::projectPoints put them; motion blur averages sub-frames over the exposure;
// read and shot noise are added in digital numbers, seeded per camera and frame; one final
// pass on the GPU does remap, noise and quantisation, or, on a software rasteriser, the CPU
// does the remap of one source view and the noise to the pixels read back
// (RendererOptions::lens_on_cpu, noise_on_cpu). Cameras without any effect take the direct
// path (no extra pass). Ground truth (depth, ids, boxes) goes through the same
// remap, so it matches the distorted colour image pixel for pixel.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/scene/scene.h"

namespace saccade::render {

/// Options of a renderer. Defaults in-class; IsValid says what is wrong.
struct RendererOptions {
  /// Multisample anti-aliasing samples per pixel: 0 (off), 2, 4 or 8.
  int msaa_samples = 0;
  /// Draw the robot's body (its own cameras never see the inside of it: near plane).
  bool draw_robot = true;
  /// Cameras to render, by name; empty: all of the scene's cameras, in scene order.
  std::vector<std::string> cameras;
  /// Levels of detail: dense meshes (1024 triangles or more) are drawn, per object and camera,
  /// at the coarsest precomputed simplification whose geometric error, projected to the image
  /// at the object's nearest point, is at most this many pixels. 0: full detail always. Finite,
  /// >= 0. The simplification keeps positions, not normals, so shading drifts faster than
  /// silhouettes: the default, a quarter pixel, keeps the bench scene's images within
  /// tests/render/lod_test.cc's tolerances and draws it about 2.5 times as fast on llvmpipe.
  double lod_max_error_px = 0.25;

  // Effects (seed section 4.3), each applied where the camera's description asks for it and
  // switched off here for every camera at once. They run on the GPU in one remap pass after
  // the scene is drawn (plus the extra scene passes motion blur needs), or on the CPU after
  // readback (lens_on_cpu, noise_on_cpu).
  /// Lens distortion of the cameras' calibrations (geometry/lens_map.h: a wider pinhole view,
  /// or a cube for lenses beyond 120 degrees, remapped). Off: every camera renders as the
  /// pinhole of its K, and the frames' metadata says distortion "none".
  bool distortion = true;
  /// Sensor noise (SensorSpec: read and shot noise, seeded per camera and frame), and a
  /// camera's EMVA 1288 sensor (SensorSpec::emva, on the CPU after readback; false: the
  /// rendered values as they are).
  bool noise = true;
  /// Where the noise is added when nothing else is left for the final pass (no lens, no float
  /// accumulation, no ground truth): on the CPU, into the pixels read back, so that the pass is
  /// skipped (true), or in the pass (false); unset: on the CPU on a software rasteriser
  /// (llvmpipe, softpipe), where a full-screen pass costs milliseconds. The same formula, table
  /// and hash either way (kFinalFragmentSource).
  std::optional<bool> noise_on_cpu;
  /// Where the lens remap is done when the camera's lens needs one source view (not a cube)
  /// and nothing was accumulated in float (the head still, or blur off) and no ground truth is
  /// drawn: on the CPU, after the source view is read back, with the noise (true), or in the
  /// final pass (false); unset: on the CPU on a software rasteriser, where the pass costs
  /// 7-10 ms an eye at 1024 x 768. The same samples either way (render/gl/internal_cpu_lens.h:
  /// within one DN of the pass).
  std::optional<bool> lens_on_cpu;
  /// Motion blur over the exposure (SensorSpec::exposure, blur_samples).
  bool motion_blur = true;
  /// The lens's photometric effects (scene::LensSpec: vignetting, depth of field), on the CPU
  /// after readback, before the sensor (render/camera_chain.h). Depth of field needs the
  /// camera's depth: the ground-truth pass's when truth is asked for (or on a GPU, with MSAA,
  /// or a lens of several source views), else the colour pass's own depth buffer, read back
  /// and remapped on the CPU (render/gl/internal_color_depth.h: no second scene pass).
  bool optics = true;
  /// The sensor's colour (scene::ColorSpec: filter array, white balance, demosaicing, tone
  /// curve), on the CPU after the sensor; Frame::raw carries the mosaic. Off: the plain RGB.
  bool color = true;
  /// Motion blur of a turning camera (a saccade): the exposure is cut into the fewest
  /// stretches whose sub-frames are each the instant drawn at the stretch's middle seen
  /// through the turn's homographies (a scene pass and a pass of fetches a stretch, instead of
  /// a scene pass a sub-frame) while what the turn alone cannot explain (the parallax of the
  /// camera's shift, items moving in the world) moves no sub-frame more than
  /// turn_blur_max_error_px from where drawing it would put it (a bound); used when that takes
  /// fewer stretches than sub-frames and the lens needs one source view (not a cube). false, or
  /// a bound of 0 with anything but a pure turn: every sub-frame drawn.
  bool turn_blur = true;
  double turn_blur_max_error_px = 1.0;  ///< finite, >= 0
  /// Where a turning camera's sub-frames are fetched through the turn when its lens is a
  /// pinhole and no ground truth is drawn: on the CPU, from the stretches read back, with the
  /// noise (true), or in the final pass (false); unset: on the CPU on a software rasteriser,
  /// where the pass cost 31-43 ms an eye of `saccade demo`. Within one DN of the pass
  /// (render/gl/internal_cpu_turn.h).
  std::optional<bool> turn_blur_on_cpu;

  /// Ground truth per frame (Frame::depth, ids, objects), consistent with the distortion:
  /// drawn at the frame's time (the middle of the exposure), without blur or noise.
  bool truth_depth = false;
  bool truth_ids = false;
  /// Objects' poses and 2D boxes (the boxes come from the id image: asking for them renders
  /// ids too).
  bool truth_objects = false;

  /// GL contexts that draw a batch (RenderBatch), each on a thread of its own with half of its
  /// images: 1 or 2; 0 (the default): 2 on a software rasteriser (llvmpipe, softpipe) when
  /// the machine has at least 2 cores, else 1. On a software rasteriser the thread that issues
  /// the draw calls (vertex work, triangle setup and binning) and the rasteriser's threads take
  /// turns, so a second issuing thread fills the cores the first leaves idle. The images are
  /// the same to the bit either way; the second context holds a copy of the scene's meshes and
  /// textures and is made at the first batch of at least four 128 x 128 images' pixels
  /// (smaller batches stay on one context: the hand-off costs more than it saves).
  int batch_contexts = 0;

  bool IsValid(std::string* error) const;
};

/// The effect switches of RendererOptions that a live renderer can change
/// (Renderer::SetEffects), each as the option of the same name.
struct EffectSwitches {
  bool distortion = true;
  bool noise = true;
  bool motion_blur = true;
  bool optics = true;
  bool color = true;

  /// The switches of `options`.
  static EffectSwitches Of(const RendererOptions& options) {
    return {options.distortion, options.noise, options.motion_blur, options.optics, options.color};
  }
  /// Sets them in `options`.
  void ApplyTo(RendererOptions* options) const {
    options->distortion = distortion;
    options->noise = noise;
    options->motion_blur = motion_blur;
    options->optics = optics;
    options->color = color;
  }
  bool operator==(const EffectSwitches& other) const {
    return distortion == other.distortion && noise == other.noise &&
           motion_blur == other.motion_blur && optics == other.optics && color == other.color;
  }
  bool operator!=(const EffectSwitches& other) const { return !(*this == other); }
};

/// Ground truth of one object (or of the robot's body) in one frame of one camera.
struct ObjectTruth {
  uint32_t id = 0;
  std::string name;  ///< the object's name, or "robot"
  /// X_WO at the frame's time (the robot: its base frame B).
  Eigen::Matrix4d X_WO = Eigen::Matrix4d::Identity();
  /// X_CO: the object in the camera's optical frame.
  Eigen::Matrix4d X_CO = Eigen::Matrix4d::Identity();
  /// Pixels of the id image that show it (0: not visible; the box is then meaningless).
  int64_t pixels = 0;
  /// Its visible 2D box in the (distorted) image, inclusive pixel indices: the smallest
  /// rectangle holding every pixel whose id is this object's.
  int x_min = 0, y_min = 0, x_max = -1, y_max = -1;
};

/// One camera's image of one state: kRgb8 pixels, row 0 at the top, with its metadata
/// (camera, time, frame index, K, distortion, X_WC, joints). Shared, never copied. Ground
/// truth is present when RendererOptions asked for it, null or empty otherwise.
struct Frame {
  std::shared_ptr<const Image> color;
  /// kFloat32, metres: the z of the surface point in the camera's optical frame (not the
  /// distance along the ray); 0 where the pixel sees no surface (sky, or no ray).
  std::shared_ptr<const Image> depth;
  /// kUint32: the instance id of the object each pixel sees (scene::Object::id, the robot's
  /// id), 0 for the background, the ground and pixels with no ray.
  std::shared_ptr<const Image> ids;
  /// Every object and the robot (when drawn), in scene order then the robot.
  std::vector<ObjectTruth> objects;
  /// The raw mosaic of a camera with a colour filter array (scene::ColorSpec::cfa, and
  /// RendererOptions::color): kBayer*8 (its pattern), white balanced, before demosaicing and
  /// the tone curve, with `color`'s metadata; null otherwise. `color` is its demosaiced image.
  std::shared_ptr<const Image> raw{};
};

/// One head of a batch (Renderer::RenderBatch): its state (time, joints) and, optionally, its
/// own placement of the scene's objects, so that every head of a batch sees its own world.
struct BatchHead {
  scene::SceneState state;
  /// Empty, or one entry per scene object (scene order): a pose X_WO that replaces the
  /// object's motion for this head; std::nullopt keeps the motion's pose at state.time.
  std::vector<std::optional<geometry::Pose>> object_poses;
  /// Empty, or one flag per scene object: true hides the object from this head's cameras.
  std::vector<bool> hidden;
};

/// Cumulative time spent per stage, for `saccade bench` (milliseconds, wall clock).
struct RenderStats {
  int64_t frames = 0;          ///< states rendered (each with every camera)
  double scene_update_ms = 0;  ///< poses, uniforms
  double draw_ms = 0;          ///< issuing draw calls (and, on llvmpipe, rasterising)
  double effects_ms = 0;       ///< issuing the remap / noise / truth passes
  double readback_ms = 0;      ///< waiting for and copying pixels out of the PBOs
  /// Of readback_ms: the lens remap and the noise done on the CPU after readback
  /// (RendererOptions::lens_on_cpu, noise_on_cpu; a software rasteriser's way).
  double cpu_effects_ms = 0;
  double total_ms = 0;
};

/// Renders the cameras of one scene. Not thread-safe: use from one thread (it owns a GL
/// context). Create with MakeRenderer.
class Renderer {
 public:
  virtual ~Renderer() = default;

  /// Renders every selected camera in `state` and returns one frame per camera, pixels in CPU
  /// memory. Equivalent to Submit followed by Retrieve.
  virtual std::vector<Frame> Render(const scene::SceneState& state, int64_t frame_index) = 0;

  /// Pipelined use: Submit starts drawing and the asynchronous readback of a state; Retrieve
  /// returns the frames of the oldest submitted state, waiting for them if needed. Keeping
  /// two states in flight overlaps the GPU's work with the caller's.
  virtual void Submit(const scene::SceneState& state, int64_t frame_index) = 0;
  virtual std::vector<Frame> Retrieve() = 0;
  /// Submitted states not yet retrieved (0, 1 or 2). Submit with 2 in flight throws Error.
  virtual int InFlight() const = 0;

  /// Switches the effects for every camera, as RendererOptions' distortion, noise,
  /// motion_blur, optics and color would at creation: the next frames are those a renderer made
  /// with these options gives, bit for bit. Only the cameras' targets are remade; the context, the
  /// uploaded models and textures and the compiled programs are kept (remaking the renderer
  /// instead costs a context and every upload, and churns over a hundred MiB on llvmpipe).
  /// Throws Error while states are in flight (Retrieve them first).
  virtual void SetEffects(const EffectSwitches& effects) = 0;

  /// Batch rendering: draws every head of `heads` through every selected camera into one
  /// framebuffer of tiles and reads them back at once into `out`: heads.size() x cameras x
  /// height x width x 3 bytes (kRgb8, row 0 at the top), tightly packed, `out_bytes` long.
  /// Every camera must have the same size. The images are the pinhole images of each camera's
  /// K (no distortion, noise or blur; no ground truth), lit as the scene says. Not pipelined:
  /// returns with the pixels in `out`. Throws InvalidArgument when the cameras' sizes differ,
  /// `out_bytes` is not the size above, a head's object_poses or hidden has neither 0 nor one
  /// entry per object, or the batch exceeds the device's framebuffer size; Error when the
  /// backend has no batch path.
  virtual void RenderBatch(const std::vector<BatchHead>& heads, uint8_t* out,
                           std::size_t out_bytes);

  /// The names of the cameras rendered, in frame order.
  virtual const std::vector<std::string>& camera_names() const = 0;
  /// "OpenGL 4.5 (Core Profile) Mesa 22.3.6, llvmpipe (LLVM 15.0.6, 256 bits)" or similar.
  virtual std::string DeviceDescription() const = 0;
  virtual const RenderStats& stats() const = 0;
};

/// Creates the OpenGL renderer for a scene: opens a surfaceless EGL display, uploads every
/// model and texture once. Throws saccade::Error with what EGL or GL said when no context can
/// be made, InvalidArgument on invalid options (naming the option) or an unknown camera name.
std::unique_ptr<Renderer> MakeRenderer(const scene::Scene& scene,
                                       const RendererOptions& options = {});

}  // namespace saccade::render
