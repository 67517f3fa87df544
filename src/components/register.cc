#include "saccade/components/register.h"

#include <filesystem>
#include <memory>

#include "components/internal_scene.h"
#include "saccade/components/accommodation_component.h"
#include "saccade/components/auto_exposure_component.h"
#include "saccade/components/debug_map.h"
#include "saccade/components/explore_components.h"
#include "saccade/components/fixation_component.h"
#include "saccade/components/hw_components.h"
#include "saccade/components/messages.h"
#include "saccade/components/remote_components.h"
#include "saccade/components/sim_components.h"
#include "saccade/components/vision_components.h"
#include "saccade/core/error.h"

namespace saccade::components {

void RegisterComponents(runtime::ComponentRegistry& registry) {
  RegisterMessages();
  internal::RegisterSceneResource(registry);
  if (registry.Has("sim.cameras")) return;
  registry.Register<SimCameras>("sim.cameras", "renders the scene's cameras (OpenGL/EGL)");
  registry.Register<SimHead>("sim.head", "the head's motors under velocity/acceleration limits");
  registry.Register<AutoExposureComponent>(
      "camera.auto_exposure", "holds a camera's brightness at a target: exposure, then gain");
  registry.Register<AccommodationComponent>("camera.accommodation",
                                            "focuses both eyes at the distance they verge to");
  registry.Register<UndistortComponent>("vision.undistort", "removes lens distortion");
  registry.Register<MedianComponent>("vision.median", "median filter");
  registry.Register<SharpenComponent>("vision.sharpen", "unsharp-mask sharpening");
  registry.Register<FaceDetectorComponent>("vision.face_detector",
                                           "Haar faces, cat faces and eyeless boxes rejected");
  registry.Register<StereoFacesComponent>("vision.stereo_faces",
                                          "left/right association and triangulation");
  registry.Register<AttentionComponent>("vision.attention", "closest face, inhibition of return");
  registry.Register<CamShiftComponent>("vision.camshift", "CamShift track of the selected face");
  registry.Register<TriangulateComponent>("vision.triangulate",
                                          "3D target from the tracks (or detections)");
  registry.Register<DenseStereoComponent>(
      "vision.dense_stereo", "dense stereo depth of the eye pair (SGBM, any vergence)");
  registry.Register<WorldMapComponent>(
      "mapping.world_map", "occupancy map of the depth (OctoMap), inhibition of return");
  registry.Register<ExploreComponent>("vision.explore",
                                      "exploration: saliency, novelty, inhibition of return");
  registry.Register<FixationComponent>("control.fixation",
                                       "inverse kinematics: saccades and smooth pursuit");
  registry.Register<HwHead>("hw.head",
                            "a real head's driver (Dynamixel bus), with its safety rules");
  registry.Register<HwCameras>("hw.cameras",
                               "real cameras (V4L2, GStreamer, IIDC, video files, image lists)");
  registry.Register<RemoteHead>("remote.head",
                                "the head of a robot process, through topics (the GUI over DDS)");
  registry.Register<RemoteCameras>("remote.cameras",
                                   "the eye cameras of a robot process, through topics");
  registry.Register<DebugFault>("debug.fault", "throws at a given step (fault injection)");
  registry.Register<DebugMap>("debug.map",
                              "a synthetic map that grows (mapping.map), to try the map's viewers");
}

runtime::ComponentRegistry RegistryWithHead(const std::string& head, const std::string& origin,
                                            const runtime::ComponentRegistry& registry) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_regular_file(head, ec)) {
    throw InvalidArgument(origin + " " + head + ": no such head file (robots/*.yaml)");
  }
  runtime::ComponentRegistry copy = registry;
  RegisterComponents(copy);
  const scene::LoadOptions options{fs::absolute(head).lexically_normal()};
  copy.ReplaceResource(
      "scene", runtime::ResourceLoader{
                   typeid(scene::Scene), "scene::Scene", [options](const std::string& path) {
                     return std::shared_ptr<const void>(
                         std::make_shared<const scene::Scene>(scene::Scene::Load(path, options)));
                   }});
  return copy;
}

}  // namespace saccade::components
