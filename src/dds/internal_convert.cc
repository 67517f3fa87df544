#include "dds/internal_convert.h"

#include <dds/ddsi/ddsi_cdrstream.h>
#include <dds/ddsi/q_protocol.h>
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "saccade/geometry/image_camera.h"
#include "saccade/head/urdf_export.h"

namespace saccade::dds::internal {

builtin_interfaces_msg_dds__Time_ ToStamp(double seconds) {
  const auto ns = static_cast<int64_t>(std::llround(seconds * 1e9));
  int64_t sec = ns / 1000000000;
  int64_t nanosec = ns % 1000000000;
  if (nanosec < 0) {  // builtin_interfaces/Time: -1.7 s is {sec: -2, nanosec: 3e8}
    nanosec += 1000000000;
    sec -= 1;
  }
  return {static_cast<int32_t>(sec), static_cast<uint32_t>(nanosec)};
}

int64_t StampNs(const builtin_interfaces_msg_dds__Time_& stamp) {
  return static_cast<int64_t>(stamp.sec) * 1000000000 + stamp.nanosec;
}

builtin_interfaces_msg_dds__Time_ ShiftStamp(const builtin_interfaces_msg_dds__Time_& stamp,
                                             int64_t offset_ns) {
  if (offset_ns == 0) return stamp;
  const int64_t ns = StampNs(stamp) + offset_ns;
  int64_t sec = ns / 1000000000;
  int64_t nanosec = ns % 1000000000;
  if (nanosec < 0) {
    nanosec += 1000000000;
    sec -= 1;
  }
  return {static_cast<int32_t>(sec), static_cast<uint32_t>(nanosec)};
}

double FromStamp(const builtin_interfaces_msg_dds__Time_& stamp) {
  return static_cast<double>(StampNs(stamp)) * 1e-9;
}

std::string OpticalFrame(const std::string& camera) { return camera + "_optical"; }

std::string CameraOfFrame(const std::string& frame) {
  static const std::string kSuffix = "_optical";
  if (frame.size() > kSuffix.size() &&
      frame.compare(frame.size() - kSuffix.size(), kSuffix.size(), kSuffix) == 0) {
    return frame.substr(0, frame.size() - kSuffix.size());
  }
  return frame;
}

std::optional<std::string> RosEncoding(PixelFormat format) {
  switch (format) {
    case PixelFormat::kGray8:
      return "mono8";
    case PixelFormat::kRgb8:
      return "rgb8";
    case PixelFormat::kRgba8:
      return "rgba8";
    case PixelFormat::kGray16:
      return "mono16";
    case PixelFormat::kFloat32:
      return "32FC1";
    case PixelFormat::kUint32:
      return std::nullopt;
    case PixelFormat::kBayerRggb8:
    case PixelFormat::kBayerBggr8:
    case PixelFormat::kBayerGbrg8:
    case PixelFormat::kBayerGrbg8:
    case PixelFormat::kBayerRggb16:
    case PixelFormat::kBayerBggr16:
    case PixelFormat::kBayerGbrg16:
    case PixelFormat::kBayerGrbg16:
      return std::string(ToString(format));  // ROS's names (sensor_msgs/image_encodings.hpp)
  }
  return std::nullopt;
}

std::optional<PixelFormat> FormatOfEncoding(const std::string& encoding) {
  if (encoding == "mono8" || encoding == "8UC1") return PixelFormat::kGray8;
  if (encoding == "rgb8" || encoding == "8UC3") return PixelFormat::kRgb8;
  if (encoding == "rgba8" || encoding == "8UC4") return PixelFormat::kRgba8;
  if (encoding == "mono16" || encoding == "16UC1") return PixelFormat::kGray16;
  if (encoding == "32FC1") return PixelFormat::kFloat32;
  for (PixelFormat bayer :
       {PixelFormat::kBayerRggb8, PixelFormat::kBayerBggr8, PixelFormat::kBayerGbrg8,
        PixelFormat::kBayerGrbg8, PixelFormat::kBayerRggb16, PixelFormat::kBayerBggr16,
        PixelFormat::kBayerGbrg16, PixelFormat::kBayerGrbg16}) {
    if (encoding == ToString(bayer)) return bayer;
  }
  return std::nullopt;
}

namespace {

char* Keep(Holder& holder, std::string text) {
  holder.strings.push_back(std::move(text));
  return holder.strings.back().data();
}

std_msgs_msg_dds__Header_ Header(double time, char* frame) { return {ToStamp(time), frame}; }

}  // namespace

bool FillImage(const Image& image, Holder& holder, sensor_msgs_msg_dds__Image_* out) {
  const std::optional<std::string> encoding = RosEncoding(image.format());
  if (!encoding) return false;
  holder.strings.reserve(8);
  const ImageMetadata& meta = image.metadata();
  out->header = Header(meta.time, Keep(holder, OpticalFrame(meta.camera)));
  out->height = static_cast<uint32_t>(image.height());
  out->width = static_cast<uint32_t>(image.width());
  out->encoding = Keep(holder, *encoding);
  out->is_bigendian = 0;  // saccade's 16- and 32-bit pixels are the machine's: little-endian
  out->step = static_cast<uint32_t>(image.stride());
  out->data._maximum = out->data._length = static_cast<uint32_t>(image.size_bytes());
  out->data._buffer = const_cast<uint8_t*>(image.data());  // written, never modified
  out->data._release = false;
  return true;
}

bool FillCompressedImage(const Image& image, const std::string& format, int jpeg_quality,
                         Holder& holder, std::vector<uint8_t>* bytes,
                         sensor_msgs_msg_dds__CompressedImage_* out) {
  const std::optional<std::string> encoding = RosEncoding(image.format());
  if (!encoding) return false;
  const bool jpeg = format == "jpeg";
  int type = 0;
  std::string compressed;  // what image_transport's plugin says the compressed pixels are
  switch (image.format()) {
    case PixelFormat::kRgb8:
      type = CV_8UC3;
      compressed = "bgr8";
      break;
    case PixelFormat::kRgba8:
      type = CV_8UC4;
      compressed = jpeg ? "bgr8" : "bgra8";
      break;
    case PixelFormat::kGray8:
      type = CV_8UC1;
      compressed = "mono8";
      break;
    case PixelFormat::kGray16:
      if (jpeg) return false;
      type = CV_16UC1;
      compressed = "mono16";
      break;
    default:
      return false;
  }
  const cv::Mat pixels(image.height(), image.width(), type, const_cast<uint8_t*>(image.data()),
                       image.stride());
  // Into a matrix of its own: the image is the pipeline's, never written.
  cv::Mat converted;
  if (image.format() == PixelFormat::kRgb8) {
    cv::cvtColor(pixels, converted, cv::COLOR_RGB2BGR);
  } else if (image.format() == PixelFormat::kRgba8) {
    cv::cvtColor(pixels, converted, jpeg ? cv::COLOR_RGBA2BGR : cv::COLOR_RGBA2BGRA);
  } else {
    converted = pixels;  // encoded as it is
  }
  std::vector<int> params;
  if (jpeg) params = {cv::IMWRITE_JPEG_QUALITY, jpeg_quality};
  if (!cv::imencode(jpeg ? ".jpg" : ".png", converted, *bytes, params)) return false;
  holder.strings.reserve(8);
  const ImageMetadata& meta = image.metadata();
  out->header = Header(meta.time, Keep(holder, OpticalFrame(meta.camera)));
  out->format = Keep(holder, *encoding + "; " + format + " compressed " + compressed);
  out->data._maximum = out->data._length = static_cast<uint32_t>(bytes->size());
  out->data._buffer = bytes->data();
  out->data._release = false;
  return true;
}

bool FillCameraInfo(const Image& image, Holder& holder, sensor_msgs_msg_dds__CameraInfo_* out) {
  const geometry::CameraModel* model = geometry::FindCameraModel(image.metadata());
  if (model == nullptr) return false;
  holder.strings.reserve(8);
  const geometry::Intrinsics& k = model->intrinsics();
  *out = {};
  out->header = Header(image.metadata().time, Keep(holder, OpticalFrame(image.metadata().camera)));
  out->height = static_cast<uint32_t>(k.height());
  out->width = static_cast<uint32_t>(k.width());
  const geometry::Distortion& distortion = model->distortion();
  std::vector<double>& d = holder.doubles[0];
  d.clear();
  // ROS's models (sensor_msgs/distortion_models.hpp) take OpenCV's coefficient order.
  if (distortion.model() == geometry::DistortionModel::kFisheye) {
    out->distortion_model = Keep(holder, "equidistant");
    d = distortion.coefficients();
  } else if (distortion.model() == geometry::DistortionModel::kRadialTangential) {
    const std::vector<double>& c = distortion.coefficients();  // k1 k2 p1 p2 k3 k4 k5 k6
    const bool rational = c.size() > 5 && (c[5] != 0 || c[6] != 0 || c[7] != 0);
    out->distortion_model = Keep(holder, rational ? "rational_polynomial" : "plumb_bob");
    d.assign(c.begin(), c.begin() + (rational ? 8 : 5));
  } else {
    out->distortion_model = Keep(holder, "plumb_bob");
    d.assign(5, 0.0);
  }
  out->d._maximum = out->d._length = static_cast<uint32_t>(d.size());
  out->d._buffer = d.data();
  out->d._release = false;
  const double K[9] = {k.fx(), k.skew(), k.cx(), 0, k.fy(), k.cy(), 0, 0, 1};
  std::memcpy(out->k, K, sizeof(K));
  const double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::memcpy(out->r, R, sizeof(R));
  // P = [K | 0]: a monocular camera (each eye is its own; the head moves the baseline).
  const double P[12] = {k.fx(), k.skew(), k.cx(), 0, 0, k.fy(), k.cy(), 0, 0, 0, 1, 0};
  std::memcpy(out->p, P, sizeof(P));
  return true;
}

bool FillCameraTransform(const Image& image, Holder& holder,
                         geometry_msgs_msg_dds__TransformStamped_* out) {
  const geometry::Pose* X_WC = geometry::FindCameraPose(image.metadata());
  if (X_WC == nullptr) return false;
  holder.strings.reserve(8);
  out->header = Header(image.metadata().time, Keep(holder, kWorldFrame));
  out->child_frame_id = Keep(holder, OpticalFrame(image.metadata().camera));
  const Eigen::Vector3d t = X_WC->translation();
  const Eigen::Quaterniond q(X_WC->rotation());
  out->transform.translation = {t.x(), t.y(), t.z()};
  out->transform.rotation = {q.x(), q.y(), q.z(), q.w()};
  return true;
}

namespace {

// Lays out a cloud of `n` points in frame "world" at `time`, each point the FLOAT32 fields
// `names` in that order, packed; returns where the points go (in holder.bytes, zeroed).
uint8_t* FillCloudLayout(double time, const std::vector<const char*>& names, std::size_t n,
                         Holder& holder, sensor_msgs_msg_dds__PointCloud2_* out) {
  holder.strings.reserve(8);
  holder.fields.clear();
  for (std::size_t i = 0; i < names.size(); ++i) {
    holder.fields.push_back(
        {const_cast<char*>(names[i]), static_cast<uint32_t>(4 * i), kPointFieldFloat32, 1});
  }
  const auto step = static_cast<uint32_t>(4 * names.size());
  holder.bytes.assign(n * step, 0);
  *out = {};
  out->header = Header(time, Keep(holder, kWorldFrame));
  out->height = 1;
  out->width = static_cast<uint32_t>(n);
  const auto f = static_cast<uint32_t>(holder.fields.size());
  out->fields = {f, f, holder.fields.data(), false};
  out->is_bigendian = false;  // the machine's floats: little-endian (CdrSerializer asserts it)
  out->point_step = step;
  out->row_step = step * static_cast<uint32_t>(n);
  const auto size = static_cast<uint32_t>(holder.bytes.size());
  out->data = {size, size, holder.bytes.data(), false};
  out->is_dense = true;  // every point is finite
  return holder.bytes.data();
}

void PutFloat(uint8_t* at, double value) {
  const auto f = static_cast<float>(value);
  std::memcpy(at, &f, sizeof(f));
}

}  // namespace

uint32_t HeightColor(double t) {
  // Blue, cyan, green, yellow, red at t = 0, 1/4, 1/2, 3/4, 1, linear between.
  static constexpr double kStops[5][3] = {{0, 0, 1}, {0, 1, 1}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}};
  const double x = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * 4.0;
  const int i = std::min(3, static_cast<int>(x));
  const double u = x - i;
  uint32_t rgb = 0;
  for (int c = 0; c < 3; ++c) {
    const double v = kStops[i][c] + u * (kStops[i + 1][c] - kStops[i][c]);
    rgb = (rgb << 8) | static_cast<uint32_t>(std::lround(255.0 * v));
  }
  return rgb;
}

void FillMapCloud(const components::MapMessage& map, Holder& holder,
                  sensor_msgs_msg_dds__PointCloud2_* out) {
  const std::vector<Eigen::Vector3d>& points = map.occupied_W;
  uint8_t* data = FillCloudLayout(map.time, {"x", "y", "z", "rgb"}, points.size(), holder, out);
  double z_min = std::numeric_limits<double>::infinity(), z_max = -z_min;
  for (const Eigen::Vector3d& p : points) {
    z_min = std::min(z_min, p.z());
    z_max = std::max(z_max, p.z());
  }
  const double range = z_max > z_min ? z_max - z_min : 1.0;
  for (const Eigen::Vector3d& p : points) {
    PutFloat(data, p.x());
    PutFloat(data + 4, p.y());
    PutFloat(data + 8, p.z());
    const uint32_t rgb = HeightColor((p.z() - z_min) / range);
    std::memcpy(data + 12, &rgb, sizeof(rgb));
    data += 16;
  }
}

void FillInhibitedCloud(const components::MapMessage& map, Holder& holder,
                        sensor_msgs_msg_dds__PointCloud2_* out) {
  uint8_t* data = FillCloudLayout(map.time, {"x", "y", "z", "strength", "radius"},
                                  map.inhibited.size(), holder, out);
  for (const components::InhibitedPlace& place : map.inhibited) {
    PutFloat(data, place.p_W.x());
    PutFloat(data + 4, place.p_W.y());
    PutFloat(data + 8, place.p_W.z());
    PutFloat(data + 12, place.strength);
    PutFloat(data + 16, place.radius_m);
    data += 20;
  }
}

bool CloudFields(const sensor_msgs_msg_dds__PointCloud2_& cloud,
                 const std::vector<std::string>& names, std::vector<double>* values,
                 std::string* error) {
  if (cloud.is_bigendian) {
    *error = "big-endian point clouds are not supported";
    return false;
  }
  struct Where {
    uint32_t offset;
    bool is_double;
  };
  std::vector<Where> where;
  for (const std::string& name : names) {
    const sensor_msgs_msg_dds__PointField_* found = nullptr;
    std::string known;
    for (uint32_t i = 0; i < cloud.fields._length; ++i) {
      const sensor_msgs_msg_dds__PointField_& f = cloud.fields._buffer[i];
      const std::string field = f.name ? f.name : "";
      known += (known.empty() ? "" : ", ") + field;
      if (field == name) found = &f;
    }
    if (found == nullptr) {
      *error = fmt::format("the cloud has no field '{}' (its fields: {})", name, known);
      return false;
    }
    const bool is_double = found->datatype == kPointFieldFloat32 + 1;  // FLOAT64
    if ((found->datatype != kPointFieldFloat32 && !is_double) || found->count > 1 ||
        uint64_t{found->offset} + (is_double ? 8 : 4) > cloud.point_step) {
      *error = fmt::format(
          "field '{}' is datatype {} count {} at offset {} of a {}-byte point; expected one "
          "FLOAT32 (7) or FLOAT64 (8) inside the point",
          name, found->datatype, found->count, found->offset, cloud.point_step);
      return false;
    }
    where.push_back({found->offset, is_double});
  }
  const uint64_t width = cloud.width, height = cloud.height;
  if (uint64_t{cloud.row_step} < width * cloud.point_step ||
      uint64_t{cloud.data._length} < uint64_t{cloud.row_step} * height) {
    *error = fmt::format("{}x{} points of {} bytes: row_step {} and {} bytes of data are too short",
                         width, height, cloud.point_step, cloud.row_step, cloud.data._length);
    return false;
  }
  values->assign(width * height * names.size(), 0.0);
  double* v = values->data();
  for (uint64_t row = 0; row < height; ++row) {
    for (uint64_t col = 0; col < width; ++col) {
      const uint8_t* point = cloud.data._buffer + row * cloud.row_step + col * cloud.point_step;
      for (const Where& w : where) {
        if (w.is_double) {
          std::memcpy(v++, point + w.offset, sizeof(double));
        } else {
          float f = 0;
          std::memcpy(&f, point + w.offset, sizeof(f));
          *v++ = f;
        }
      }
    }
  }
  return true;
}

namespace {

bool CheckWorldFrame(const sensor_msgs_msg_dds__PointCloud2_& cloud, std::string* error) {
  const std::string frame = cloud.header.frame_id ? cloud.header.frame_id : "";
  if (frame == kWorldFrame) return true;
  *error = "point cloud in frame '" + frame + "', expected 'world'";
  return false;
}

}  // namespace

bool MapOf(const sensor_msgs_msg_dds__PointCloud2_& cloud, components::MapMessage* map,
           std::string* error) {
  std::vector<double> v;
  if (!CheckWorldFrame(cloud, error) || !CloudFields(cloud, {"x", "y", "z"}, &v, error)) {
    return false;
  }
  *map = {};
  map->time = FromStamp(cloud.header.stamp);
  map->occupied_W.reserve(v.size() / 3);
  for (std::size_t i = 0; i + 2 < v.size(); i += 3) {
    map->occupied_W.emplace_back(v[i], v[i + 1], v[i + 2]);
  }
  return true;
}

bool InhibitedOf(const sensor_msgs_msg_dds__PointCloud2_& cloud,
                 std::vector<components::InhibitedPlace>* places, std::string* error) {
  std::vector<double> v;
  if (!CheckWorldFrame(cloud, error) ||
      !CloudFields(cloud, {"x", "y", "z", "strength", "radius"}, &v, error)) {
    return false;
  }
  places->clear();
  for (std::size_t i = 0; i + 4 < v.size(); i += 5) {
    places->push_back({Eigen::Vector3d(v[i], v[i + 1], v[i + 2]), v[i + 4], v[i + 3]});
  }
  return true;
}

void FillLinkTransforms(double time, const head::HeadModel& head, const head::JointState& positions,
                        Holder& holder,
                        std::vector<geometry_msgs_msg_dds__TransformStamped_>* out) {
  const head::KinematicTree& tree = head.tree();
  std::vector<geometry::Pose> X_WL;
  head.ForwardKinematics(head.Posture(positions), &X_WL);
  out->clear();
  out->reserve(tree.num_links());
  // Every frame name once, before any pointer into them is taken (no reallocation after).
  holder.strings.clear();
  holder.strings.reserve(tree.num_links() + 1);
  holder.strings.emplace_back(kWorldFrame);
  for (int link = 0; link < tree.num_links(); ++link)
    holder.strings.push_back(tree.link_name(link));
  const auto frame = [&holder](int link) { return holder.strings[link + 1].data(); };
  const auto Add = [&](char* parent, char* child, const geometry::Pose& X_PC) {
    geometry_msgs_msg_dds__TransformStamped_ t{};
    t.header = Header(time, parent);
    t.child_frame_id = child;
    const Eigen::Vector3d p = X_PC.translation();
    const Eigen::Quaterniond q(X_PC.rotation());
    t.transform.translation = {p.x(), p.y(), p.z()};
    t.transform.rotation = {q.x(), q.y(), q.z(), q.w()};
    out->push_back(t);
  };
  Add(holder.strings[0].data(), frame(tree.root()), X_WL[tree.root()]);
  for (const int j : tree.joint_order()) {
    const head::KinematicTree::Joint& joint = tree.joint(j);
    Add(frame(joint.parent), frame(joint.child), X_WL[joint.parent].inverse() * X_WL[joint.child]);
  }
}

std::string RobotDescription(const head::HeadModel& head) {
  return head.urdf_xml().empty() ? head::ExportUrdf(head).xml : head.urdf_xml();
}

std::optional<geometry::CameraModel> CameraModelOf(const sensor_msgs_msg_dds__CameraInfo_& info,
                                                   std::string* error) {
  const std::string model = info.distortion_model ? info.distortion_model : "";
  const std::vector<double> d(info.d._buffer, info.d._buffer + info.d._length);
  try {
    const geometry::Intrinsics k(static_cast<int>(info.width), static_cast<int>(info.height),
                                 info.k[0], info.k[4], info.k[2], info.k[5], info.k[1]);
    bool zero = true;
    for (double c : d) zero = zero && c == 0.0;
    if (d.empty() || zero) return geometry::CameraModel(k);
    if (model == "equidistant") {
      return geometry::CameraModel(k, geometry::Distortion::Fisheye(d));
    }
    if (model == "plumb_bob" || model == "rational_polynomial") {
      return geometry::CameraModel(k, geometry::Distortion::RadialTangential(d));
    }
    if (error) *error = "unknown distortion model '" + model + "'";
  } catch (const std::exception& e) {
    if (error) *error = e.what();
  }
  return std::nullopt;
}

geometry::Pose PoseOf(const geometry_msgs_msg_dds__Transform_& transform) {
  const auto& r = transform.rotation;
  const auto& t = transform.translation;
  const Eigen::Quaterniond q = Eigen::Quaterniond(r.w, r.x, r.y, r.z).normalized();
  return geometry::MakePose(q.toRotationMatrix(), Eigen::Vector3d(t.x, t.y, t.z));
}

namespace {

// XCDR1 read cursor: alignment counts from after the encapsulation header.
class CdrCursor {
 public:
  CdrCursor(const uint8_t* bytes, std::size_t size, bool swap)
      : bytes_(bytes), size_(size), swap_(swap) {}
  std::size_t pos() const { return pos_; }
  bool U32(uint32_t* v) {
    pos_ = 4 + ((pos_ - 4 + 3) / 4) * 4;
    if (pos_ > size_ || size_ - pos_ < 4) return false;
    std::memcpy(v, bytes_ + pos_, 4);
    if (swap_) *v = __builtin_bswap32(*v);
    pos_ += 4;
    return true;
  }
  bool U8(uint8_t* v) {
    if (pos_ >= size_) return false;
    *v = bytes_[pos_++];
    return true;
  }
  // A string: its length (with the NUL), its bytes, NUL-terminated in place.
  bool String(char** s) {
    uint32_t length = 0;
    if (!U32(&length) || length > size_ - pos_) return false;
    if (length == 0) {
      *s = const_cast<char*>("");
      return true;
    }
    if (bytes_[pos_ + length - 1] != 0) return false;
    *s = reinterpret_cast<char*>(const_cast<uint8_t*>(bytes_ + pos_));
    pos_ += length;
    return true;
  }
  // A sequence<uint8>: its length, then its bytes in place.
  bool Bytes(uint32_t* length, const uint8_t** data) {
    if (!U32(length) || *length > size_ - pos_) return false;
    *data = bytes_ + pos_;
    pos_ += *length;
    return true;
  }

 private:
  const uint8_t* bytes_;
  std::size_t size_;
  bool swap_;
  std::size_t pos_ = 4;
};

}  // namespace

bool ImageViewOfCdr(const uint8_t* cdr, std::size_t size, sensor_msgs_msg_dds__Image_* out,
                    std::string* error) {
  *out = {};
  if (size < 4) {
    *error = fmt::format("{} bytes: shorter than the encapsulation header", size);
    return false;
  }
  // Encapsulation: 0x0000 CDR big-endian, 0x0001 CDR little-endian (XCDR1, as ROS 2 writes).
  const unsigned id = (unsigned{cdr[0]} << 8) | cdr[1];
  if (id != 0x0000 && id != 0x0001) {
    *error = fmt::format("encapsulation 0x{:04x} is not plain CDR (0x0000 or 0x0001)", id);
    return false;
  }
  const bool little = id == 0x0001;
  CdrCursor c(cdr, size, little != (std::endian::native == std::endian::little));
  uint32_t sec = 0, nanosec = 0, data_length = 0;
  uint8_t is_bigendian = 0;
  const uint8_t* data = nullptr;
  const auto Fail = [&](const char* what) {
    *error = fmt::format("sensor_msgs/Image of {} bytes ends inside its {} (byte {})", size, what,
                         c.pos());
    return false;
  };
  if (!c.U32(&sec) || !c.U32(&nanosec)) return Fail("header.stamp");
  if (!c.String(&out->header.frame_id)) return Fail("header.frame_id");
  if (!c.U32(&out->height) || !c.U32(&out->width)) return Fail("height and width");
  if (!c.String(&out->encoding)) return Fail("encoding");
  if (!c.U8(&is_bigendian)) return Fail("is_bigendian");
  if (!c.U32(&out->step)) return Fail("step");
  if (!c.Bytes(&data_length, &data)) return Fail("data");
  out->header.stamp = {static_cast<int32_t>(sec), nanosec};
  out->is_bigendian = is_bigendian;
  out->data = {data_length, data_length, const_cast<uint8_t*>(data), false};
  return true;
}

CdrSerializer::CdrSerializer() { dds_ostream_init(&os_, 4096, CDR_ENC_VERSION_1); }

CdrSerializer::~CdrSerializer() { dds_ostream_fini(&os_); }

std::span<const uint8_t> CdrSerializer::Serialize(const dds_topic_descriptor_t& descriptor,
                                                  const void* sample) {
  static_assert(std::endian::native == std::endian::little, "CDR_LE header below");
  // The body starts at byte 8 of the buffer: XCDR1 aligns to at most 8 bytes from the first
  // byte after the header, which is then aligned as the buffer is. The header goes in 4..7.
  constexpr uint32_t kBody = 8;
  os_.m_index = kBody;  // the buffer holds 4096 bytes from the start, and grows as needed
  dds_stream_write(&os_, static_cast<const char*>(sample), descriptor.m_ops);
  uint8_t* buffer = os_.m_buffer;
  buffer[4] = 0x00;  // CDR_LE: 0x0001, big-endian on the wire, then two option bytes
  buffer[5] = 0x01;
  buffer[6] = buffer[7] = 0x00;
  return {buffer + 4, os_.m_index - 4};
}

bool DeserializeCdr(const dds_topic_descriptor_t& descriptor, const uint8_t* data, std::size_t size,
                    void* sample, std::string* error) {
  if (size < 4) {
    *error = fmt::format("{} bytes: shorter than the encapsulation header", size);
    return false;
  }
  if (size > std::numeric_limits<uint32_t>::max()) {
    *error = fmt::format("{} bytes: more than CDR's 4 GiB", size);
    return false;
  }
  const unsigned id = (unsigned{data[0]} << 8) | data[1];
  if (id != 0x0000 && id != 0x0001) {
    *error = fmt::format("encapsulation 0x{:04x} is not plain CDR (0x0000 or 0x0001)", id);
    return false;
  }
  const bool little = id == 0x0001;
  // Checked (and put in this machine's byte order) in a copy: normalizing writes in place.
  std::vector<char> body(data + 4, data + size);
  uint32_t end = 0;
  if (dds_stream_normalize_data(body.data(), &end, static_cast<uint32_t>(body.size()),
                                little != (std::endian::native == std::endian::little),
                                CDR_ENC_VERSION_1, descriptor.m_ops) == nullptr) {
    *error =
        fmt::format("{} bytes that are not one whole {}", size, RosTypeName(descriptor.m_typename));
    return false;
  }
  dds_istream_t is;
  dds_istream_init(&is, static_cast<uint32_t>(body.size()), body.data(), CDR_ENC_VERSION_1);
  dds_stream_read(&is, static_cast<char*>(sample), descriptor.m_ops);
  dds_istream_fini(&is);
  return true;
}

std::string RosTypeName(const std::string& dds_type_name) {
  // pkg::msg::dds_::Type_ -> pkg/msg/Type
  std::string name = dds_type_name;
  const std::string dds_part = "::dds_::";
  if (const auto at = name.find(dds_part); at != std::string::npos) {
    name.replace(at, dds_part.size(), "::");
  }
  if (!name.empty() && name.back() == '_') name.pop_back();
  for (std::size_t at; (at = name.find("::")) != std::string::npos;) name.replace(at, 2, "/");
  return name;
}

std::shared_ptr<Image> ImagePool::Get(int width, int height, PixelFormat format) {
  for (std::shared_ptr<Image>& image : images_) {
    if (image.use_count() != 1) continue;  // still held by whoever it was handed to
    if (image->width() != width || image->height() != height || image->format() != format) {
      image = std::make_shared<Image>(width, height, format);  // the stream changed size
    }
    image->metadata() = ImageMetadata{};
    return image;
  }
  auto image = std::make_shared<Image>(width, height, format);
  if (images_.size() < capacity_) {
    images_.push_back(image);
  } else if (capacity_ > 0) {
    images_[next_] = image;  // the one it replaces lives on with its holders
    next_ = (next_ + 1) % capacity_;
  }
  return image;
}

std::shared_ptr<Image> ImageOf(const sensor_msgs_msg_dds__Image_& msg, std::string* error,
                               ImagePool* pool) {
  const std::string encoding = msg.encoding ? msg.encoding : "";
  const std::optional<PixelFormat> format = FormatOfEncoding(encoding);
  if (!format) {
    *error = "encoding '" + encoding +
             "' is not one of mono8, rgb8, rgba8, mono16, 32FC1, bayer_{rggb,bggr,gbrg,grbg}{8,16}";
    return nullptr;
  }
  if (msg.is_bigendian && BytesPerPixel(*format) > 1) {
    *error = "big-endian " + encoding + " images are not supported";
    return nullptr;
  }
  if (msg.width > static_cast<uint32_t>(std::numeric_limits<int>::max()) ||
      msg.height > static_cast<uint32_t>(std::numeric_limits<int>::max())) {
    *error = fmt::format("a {}x{} image is too large", msg.width, msg.height);
    return nullptr;
  }
  const std::size_t row = static_cast<std::size_t>(msg.width) * BytesPerPixel(*format);
  if (msg.step < row || static_cast<std::size_t>(msg.data._length) <
                            static_cast<std::size_t>(msg.step) * msg.height) {
    *error = fmt::format("{}x{} {} image: step {} and {} bytes of data are too short", msg.width,
                         msg.height, encoding, msg.step, msg.data._length);
    return nullptr;
  }
  const int width = static_cast<int>(msg.width), height = static_cast<int>(msg.height);
  std::shared_ptr<Image> image;
  if (pool == nullptr) {
    // One copy out of Cyclone's sample, rows packed (no zero-fill first).
    image = std::make_shared<Image>(width, height, *format, msg.data._buffer, msg.step);
  } else {
    image = pool->Get(width, height, *format);
    if (row > 0 && msg.step == row) {
      std::memcpy(image->data(), msg.data._buffer, row * height);
    } else if (row > 0) {
      for (int y = 0; y < height; ++y) {
        std::memcpy(image->row(y), msg.data._buffer + std::size_t{msg.step} * y, row);
      }
    }
  }
  image->metadata().camera = CameraOfFrame(msg.header.frame_id ? msg.header.frame_id : "");
  image->metadata().time = FromStamp(msg.header.stamp);
  return image;
}

void FillJointState(double time, const head::JointState& positions,
                    const head::JointState* velocities, Holder& holder,
                    sensor_msgs_msg_dds__JointState_* out) {
  holder.strings.reserve(8);
  *out = {};
  out->header = Header(time, Keep(holder, ""));
  holder.string_pointers.clear();
  holder.doubles[0].clear();
  holder.doubles[1].clear();
  // The names live in the states' shared name lists, which outlive the write.
  for (int joint = 0; joint < positions.size(); ++joint) {
    holder.string_pointers.push_back(const_cast<char*>(positions.name(joint).c_str()));
    holder.doubles[0].push_back(positions[joint]);
    if (velocities && velocities->size() == positions.size()) {
      holder.doubles[1].push_back((*velocities)[joint]);
    }
  }
  const auto n = static_cast<uint32_t>(positions.size());
  out->name = {n, n, n ? holder.string_pointers.data() : nullptr, false};
  out->position = {n, n, n ? holder.doubles[0].data() : nullptr, false};
  const auto nv = static_cast<uint32_t>(holder.doubles[1].size());
  out->velocity = {nv, nv, nv ? holder.doubles[1].data() : nullptr, false};
  out->effort = {0, 0, nullptr, false};
}

bool ArrivedOn(const head::JointState& positions, const head::JointState& velocities,
               const head::JointState& targets, const head::JointState& target_velocities) {
  constexpr double kTolerance = 1e-4;            // sim.head's (SimHead::State)
  const bool still = target_velocities.empty();  // empty: the targets stand still
  if (targets.size() != positions.size() || velocities.size() != positions.size() ||
      (!still && target_velocities.size() != positions.size())) {
    return false;
  }
  for (int joint = 0; joint < positions.size(); ++joint) {
    const double target_velocity = still ? 0.0 : target_velocities[joint];
    if (!(std::abs(positions[joint] - targets[joint]) <= kTolerance &&
          std::abs(velocities[joint] - target_velocity) <= kTolerance)) {
      return false;
    }
  }
  return true;
}

void TargetsToSend(const components::JointStateMessage& m, head::JointState* targets,
                   head::JointState* target_velocities) {
  const bool here =
      m.arrived && !ArrivedOn(m.positions, m.velocities, m.targets, m.target_velocities);
  *targets = here ? m.positions : m.targets;
  *target_velocities = here ? m.velocities : m.target_velocities;
}

bool JointsOf(const sensor_msgs_msg_dds__JointState_& msg, head::JointState* positions,
              head::JointState* velocities, std::string* error) {
  const uint32_t n = msg.name._length;
  if (msg.position._length != n || (msg.velocity._length != 0 && msg.velocity._length != n)) {
    *error = fmt::format("{} names, {} positions and {} velocities", n, msg.position._length,
                         msg.velocity._length);
    return false;
  }
  // The message's names, in its order: the receiver arranges them in its head's order by name
  // (HeadModel::Arrange), which names unknown and missing joints.
  auto names = std::make_shared<head::JointNames>();
  Eigen::VectorXd p(n), v = Eigen::VectorXd::Zero(n);
  for (uint32_t i = 0; i < n; ++i) {
    const std::string name = msg.name._buffer[i] ? msg.name._buffer[i] : "";
    if (name.empty() || std::find(names->begin(), names->end(), name) != names->end()) {
      *error = name.empty() ? std::string("a joint without a name")
                            : fmt::format("joint '{}' named twice", name);
      return false;
    }
    names->push_back(name);
    p[i] = msg.position._buffer[i];
    if (msg.velocity._length) v[i] = msg.velocity._buffer[i];
  }
  std::shared_ptr<const head::JointNames> shared = std::move(names);
  *positions = head::JointState(shared, std::move(p));
  *velocities = head::JointState(shared, std::move(v));
  return true;
}

}  // namespace saccade::dds::internal
