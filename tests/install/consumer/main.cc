// Forward kinematics and a render through an installed saccade: consumer SCENE.
#include <saccade/head/head_model.h>
#include <saccade/render/renderer.h>
#include <saccade/scene/scene.h>

#include <cstdio>

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const saccade::scene::Scene scene = saccade::scene::Scene::Load(argv[1]);
  const auto cameras = scene.robot()->head.CameraPoses(scene.robot()->initial_joints);
  const auto images = saccade::render::MakeRenderer(scene, {})->Render(scene.InitialState(), 0);
  const saccade::Image& left = *images.at(0).color;
  std::printf("left camera at %.4f %.4f %.4f, image %dx%d, first pixel %d\n",
              cameras[0].translation().x(), cameras[0].translation().y(),
              cameras[0].translation().z(), left.width(), left.height(), left.row(0)[0]);
  return 0;
}
