// saccade.render: the OpenGL renderer (headless EGL), its frames as numpy arrays without a
// copy (ground truth included), render(out=) into a caller's array, and batch rendering.
// Rendering releases the GIL.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cstring>

#include "python/internal_bindings.h"
#include "saccade/core/error.h"
#include "saccade/render/renderer.h"

namespace saccade::python {
namespace {

// A caller's array that receives `shape` of uint8: C-contiguous, writable, exactly that shape.
uint8_t* CheckOut(const py::array& out, const std::vector<py::ssize_t>& shape, const char* who) {
  std::string want;
  for (py::ssize_t n : shape) want += (want.empty() ? "" : ", ") + std::to_string(n);
  std::string got;
  for (py::ssize_t i = 0; i < out.ndim(); ++i) {
    got += (got.empty() ? "" : ", ") + std::to_string(out.shape(i));
  }
  if (!out.dtype().equal(py::dtype::of<uint8_t>()) ||
      out.ndim() != static_cast<py::ssize_t>(shape.size()) ||
      !std::equal(shape.begin(), shape.end(), out.shape())) {
    throw InvalidArgument(std::string(who) + ": out must be a uint8 array of shape (" + want +
                          "); got " + std::string(py::str(out.dtype())) + " of shape (" + got +
                          ")");
  }
  if (!(out.flags() & py::array::c_style) || !out.writeable()) {
    throw InvalidArgument(std::string(who) + ": out must be C-contiguous and writable");
  }
  return static_cast<uint8_t*>(const_cast<void*>(out.data()));
}

// The renderer and what it needs to stay valid.
struct PyRenderer {
  std::shared_ptr<const scene::Scene> scene;
  std::unique_ptr<render::Renderer> renderer;
  int width = 0, height = 0;  // of the first camera
};

// Renderer.render: every camera's Frame, or (out=) their colour images into the caller's array.
py::object Render(PyRenderer& r, const scene::SceneState& state, int64_t frame_index,
                  std::optional<py::array> out) {
  using render::Frame;
  std::vector<Frame> frames;
  uint8_t* target = nullptr;
  std::size_t bytes = 0;
  if (out) {
    const auto cameras = static_cast<py::ssize_t>(r.renderer->camera_names().size());
    target = CheckOut(*out, {cameras, r.height, r.width, 3}, "Renderer.render");
    bytes = static_cast<std::size_t>(r.height) * r.width * 3;
  }
  {
    py::gil_scoped_release release;
    frames = r.renderer->Render(state, frame_index);
    if (target != nullptr) {
      for (std::size_t i = 0; i < frames.size(); ++i) {
        const Image& color = *frames[i].color;
        if (color.size_bytes() != bytes) {
          throw InvalidArgument(
              "Renderer.render: out= needs every camera at the "
              "first camera's size; camera '" +
              r.renderer->camera_names()[i] + "' differs");
        }
        std::memcpy(target + i * bytes, color.data(), bytes);
      }
    }
  }
  if (out) return *out;
  return py::cast(std::move(frames));
}

// A camera's frame and its ground truth.
void BindFrames(py::module_& m) {
  using namespace render;
  py::class_<ObjectTruth>(m, "ObjectTruth", "Ground truth of one object in one frame.")
      .def_readonly("id", &ObjectTruth::id)
      .def_readonly("name", &ObjectTruth::name)
      .def_property_readonly("X_WO", [](const ObjectTruth& t) { return t.X_WO; })
      .def_property_readonly("X_CO", [](const ObjectTruth& t) { return t.X_CO; })
      .def_readonly("pixels", &ObjectTruth::pixels, "Pixels of the id image that show it.")
      .def_property_readonly(
          "box",
          [](const ObjectTruth& t) { return py::make_tuple(t.x_min, t.y_min, t.x_max, t.y_max); },
          "(x_min, y_min, x_max, y_max), inclusive pixel indices.");

  py::class_<Frame>(m, "Frame",
                    "One camera's image of one state. The arrays are numpy views of the C++ "
                    "images (no copy, read-only); their base is the saccade.Image that owns "
                    "them, which also carries the metadata (camera, time, K, X_WC, joints).")
      .def_property_readonly(
          "color", [](const Frame& f) { return ImageArray(f.color); },
          "height x width x 3 uint8, row 0 at the top.")
      .def_property_readonly(
          "depth", [](const Frame& f) { return ImageArray(f.depth); },
          "height x width float32, metres (z in the camera frame), or None.")
      .def_property_readonly(
          "ids", [](const Frame& f) { return ImageArray(f.ids); },
          "height x width uint32 instance ids, or None.")
      .def_property_readonly(
          "image",
          [](const Frame& f) -> py::object {
            return f.color ? py::cast(ImageRef{f.color}) : py::none();
          },
          "The colour image's owner, with its metadata.")
      .def_property_readonly(
          "raw", [](const Frame& f) { return ImageArray(f.raw); },
          "The raw mosaic of a camera with a colour filter array: height x width uint8, white "
          "balanced, before demosaicing and the tone curve (its pattern: raw_format); None "
          "without a filter, or with color=False.")
      .def_property_readonly(
          "raw_format",
          [](const Frame& f) -> py::object {
            if (!f.raw) return py::none();
            return py::str(std::string(ToString(f.raw->format())));
          },
          "The mosaic's pattern as its ROS encoding ('bayer_rggb8', 'bayer_bggr8', "
          "'bayer_gbrg8', 'bayer_grbg8'), or None.")
      .def_readonly("objects", &Frame::objects);
}

// The renderer's time per stage.
void BindRenderStats(py::module_& m) {
  using namespace render;
  py::class_<RenderStats>(m, "RenderStats", "Cumulative time per stage, milliseconds.")
      .def_readonly("frames", &RenderStats::frames)
      .def_readonly("scene_update_ms", &RenderStats::scene_update_ms)
      .def_readonly("draw_ms", &RenderStats::draw_ms)
      .def_readonly("effects_ms", &RenderStats::effects_ms)
      .def_readonly("readback_ms", &RenderStats::readback_ms)
      .def_readonly("cpu_effects_ms", &RenderStats::cpu_effects_ms,
                    "Of readback_ms: the lens remap and the noise done on the CPU (a software "
                    "rasteriser's way).")
      .def_readonly("total_ms", &RenderStats::total_ms);
}

// One head of a batch render.
void BindBatchHead(py::module_& m) {
  using namespace render;
  py::class_<BatchHead>(m, "BatchHead",
                        "One head of a batch: its state and, optionally, per scene object a "
                        "4x4 pose replacing its motion (None: keep it) and a hidden flag.")
      .def(py::init([](const scene::SceneState& state,
                       const std::optional<std::vector<std::optional<Eigen::Matrix4d>>>& poses,
                       const std::optional<std::vector<bool>>& hidden) {
             BatchHead head;
             head.state = state;
             if (poses) {
               for (std::size_t i = 0; i < poses->size(); ++i) {
                 const auto& pose = (*poses)[i];
                 head.object_poses.push_back(
                     pose ? std::optional<geometry::Pose>(PoseFromMatrix(
                                *pose,
                                ("BatchHead: object_poses[" + std::to_string(i) + "]").c_str()))
                          : std::nullopt);
               }
             }
             if (hidden) head.hidden = *hidden;
             return head;
           }),
           "state"_a, "object_poses"_a = py::none(), "hidden"_a = py::none())
      .def_readwrite("state", &BatchHead::state);
}

// The renderer.
void BindRenderer(py::module_& m) {
  using namespace render;
  py::class_<PyRenderer>(m, "Renderer",
                         "Renders a scene's cameras headless (OpenGL 3.3 through EGL: llvmpipe "
                         "without a GPU). Not thread-safe: use it from one thread.")
      .def(py::init([](std::shared_ptr<scene::Scene> scene,
                       const std::optional<std::vector<std::string>>& cameras, int msaa_samples,
                       bool draw_robot, bool distortion, bool noise, bool motion_blur, bool optics,
                       bool color, bool truth_depth, bool truth_ids, bool truth_objects,
                       double lod_max_error_px, int batch_contexts) {
             RendererOptions options;
             if (cameras) options.cameras = *cameras;
             options.msaa_samples = msaa_samples;
             options.draw_robot = draw_robot;
             options.distortion = distortion;
             options.noise = noise;
             options.motion_blur = motion_blur;
             options.optics = optics;
             options.color = color;
             options.truth_depth = truth_depth;
             options.truth_ids = truth_ids;
             options.truth_objects = truth_objects;
             options.lod_max_error_px = lod_max_error_px;
             options.batch_contexts = batch_contexts;
             auto result = std::make_unique<PyRenderer>();
             result->scene = scene;
             {
               py::gil_scoped_release release;
               result->renderer = MakeRenderer(*scene, options);
             }
             const scene::CameraSpec* first =
                 scene->FindCamera(result->renderer->camera_names().front());
             result->width = first->model.intrinsics().width();
             result->height = first->model.intrinsics().height();
             return result;
           }),
           "scene"_a, "cameras"_a = py::none(), "msaa_samples"_a = 0, "draw_robot"_a = true,
           "distortion"_a = true, "noise"_a = true, "motion_blur"_a = true, "optics"_a = true,
           "color"_a = true, "truth_depth"_a = false, "truth_ids"_a = false,
           "truth_objects"_a = false, "lod_max_error_px"_a = 0.25, "batch_contexts"_a = 0,
           "Opens a surfaceless EGL context and uploads the scene. `cameras`: names, default "
           "all. `optics`: the lenses' vignetting and depth of field; `color`: the sensors' "
           "colour filter array, white balance, demosaicing and tone curve (Frame.raw). "
           "`batch_contexts`: GL contexts that draw a render_batch, each on a thread of its "
           "own (1 or 2; 0: 2 on a software rasteriser with 2 cores or more; the images are the "
           "same to the bit). Raises InvalidArgument naming a bad option or an unknown camera.")
      .def_property_readonly("camera_names",
                             [](const PyRenderer& r) { return r.renderer->camera_names(); })
      .def_property_readonly("device",
                             [](const PyRenderer& r) { return r.renderer->DeviceDescription(); })
      .def_property_readonly("stats", [](const PyRenderer& r) { return r.renderer->stats(); })
      .def(
          "set_effects",
          [](PyRenderer& r, bool distortion, bool noise, bool motion_blur, bool optics,
             bool color) {
            py::gil_scoped_release release;
            r.renderer->SetEffects({distortion, noise, motion_blur, optics, color});
          },
          "distortion"_a, "noise"_a, "motion_blur"_a, "optics"_a = true, "color"_a = true,
          "Switches the effects of every camera in place, as the constructor's arguments would: "
          "the next renders are bit for bit those of a Renderer made with them, without a new "
          "context or uploads (say, effects drawn at random per episode).")
      .def("render", &Render, "state"_a, "frame_index"_a = 0, "out"_a = py::none(),
           "Renders every camera in `state`. Returns one Frame per camera; with out= (a uint8 "
           "array cameras x height x width x 3) fills it instead and returns it. Releases the GIL.")
      .def(
          "render_batch",
          [](PyRenderer& r, const std::vector<BatchHead>& heads, std::optional<py::array> out) {
            const auto cameras = static_cast<py::ssize_t>(r.renderer->camera_names().size());
            const std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(heads.size()), cameras,
                                                 r.height, r.width, 3};
            py::array result = out ? *out : py::array(py::dtype::of<uint8_t>(), shape);
            uint8_t* target = CheckOut(result, shape, "Renderer.render_batch");
            const std::size_t bytes = static_cast<std::size_t>(result.nbytes());
            {
              py::gil_scoped_release release;
              r.renderer->RenderBatch(heads, target, bytes);
            }
            return result;
          },
          "heads"_a, "out"_a = py::none(),
          "Draws every head (BatchHead: its own state, object poses, hidden objects) through "
          "every camera in one call and one readback. Returns (or fills) a uint8 array heads x "
          "cameras x height x width x 3: the pinhole images of K (no distortion, noise or "
          "blur). Releases the GIL.");
}

}  // namespace

void BindRender(py::module_& m) {
  BindFrames(m);
  BindRenderStats(m);
  BindBatchHead(m);
  BindRenderer(m);
}

}  // namespace saccade::python
