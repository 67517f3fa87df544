#include "saccade/components/demo/loop_outputs.h"

namespace saccade::components::demo {

void TapLoopOutputs(runtime::Pipeline& pipeline, Latest* latest) {
  Tap<runtime::ImageMessage>(pipeline, [latest](const runtime::ImageMessage& m) {
    // A raw mosaic (sim.cameras' `raw`) carries its camera's name too: the camera's image is
    // the demosaiced one.
    if (m.image && !IsBayer(m.image->format()))
      latest->images[m.image->metadata().camera] = m.image;
  });
  Tap<FacesMessage>(pipeline, [latest](const FacesMessage& m) {
    if (m.image) latest->faces[m.image->metadata().camera] = m;
  });
  Tap<TrackMessage>(pipeline, [latest](const TrackMessage& m) {
    if (m.image) latest->tracks[m.image->metadata().camera] = m;
  });
  Tap<SelectionMessage>(pipeline, [latest](const SelectionMessage& m) { latest->selection = m; });
  Tap<TargetMessage>(pipeline, [latest](const TargetMessage& m) { latest->target = m; });
  Tap<JointStateMessage>(pipeline, [latest](const JointStateMessage& m) { latest->joints = m; });
}

}  // namespace saccade::components::demo
