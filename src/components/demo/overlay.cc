#include "saccade/components/demo/overlay.h"

#include <opencv2/imgproc.hpp>

#include "saccade/vision/image_camera.h"

namespace saccade::components::demo {

cv::Mat Annotate(const Latest& latest, const std::string& camera, double scale) {
  const auto it = latest.images.find(camera);
  if (it == latest.images.end() || !it->second) {
    return cv::Mat(static_cast<int>(768 * scale), static_cast<int>(1024 * scale), CV_8UC3,
                   cv::Scalar(0));
  }
  const Image& image = *it->second;
  cv::Mat rgb(image.height(), image.width(), CV_8UC3, const_cast<uint8_t*>(image.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  const int64_t frame = image.metadata().frame_index;
  if (const auto f = latest.faces.find(camera); f != latest.faces.end() && f->second.image &&
                                                f->second.image->metadata().frame_index == frame) {
    for (const FacesMessage::Face& face : f->second.faces) {
      const cv::Scalar color = face.rejected ? cv::Scalar(0, 0, 255) : cv::Scalar(0, 220, 0);
      cv::rectangle(bgr, face.box, color, 3);
      if (face.rejected) {
        cv::putText(bgr, face.reason, face.box.tl() + cv::Point(0, -8), cv::FONT_HERSHEY_SIMPLEX,
                    0.9, color, 2);
      }
    }
  }
  if (const auto t = latest.tracks.find(camera); t != latest.tracks.end() && t->second.tracking) {
    cv::rectangle(bgr, t->second.window, cv::Scalar(0, 220, 255), 2);
  }
  if (latest.target && latest.target->valid) {
    const geometry::CameraModel model = vision::CameraModelOf(image);
    const Eigen::Vector3d p_C = vision::CameraPoseOf(image).inverse() * latest.target->p_W;
    if (p_C.z() > 0.0) {
      if (const auto uv = model.Project(p_C)) {
        cv::circle(bgr, cv::Point(static_cast<int>(uv->x()), static_cast<int>(uv->y())), 10,
                   cv::Scalar(255, 255, 0), 3);
      }
    }
  }
  // The image centre: where a fixated target lands.
  cv::drawMarker(bgr, cv::Point(image.width() / 2, image.height() / 2), cv::Scalar(255, 255, 255),
                 cv::MARKER_CROSS, 30, 2);
  if (scale == 1.0) return bgr;
  cv::Mat scaled;
  cv::resize(bgr, scaled,
             cv::Size(static_cast<int>(bgr.cols * scale), static_cast<int>(bgr.rows * scale)), 0, 0,
             cv::INTER_AREA);
  return scaled;
}

}  // namespace saccade::components::demo
