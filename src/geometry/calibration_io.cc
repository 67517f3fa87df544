#include "saccade/geometry/calibration_io.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <Eigen/LU>
#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <system_error>
#include <vector>

#include "core/internal_yaml.h"
#include "internal_opencv_storage.h"
#include "saccade/core/error.h"
#include "saccade/core/temporary_file.h"

namespace saccade::geometry {
namespace {

using internal::StorageNode;

// stereoCalibrate's R is orthonormal to ~1e-15; a file printed with 6 significant digits is
// orthonormal to ~2e-6. Anything further off is not a rotation matrix.
constexpr double kRotationTolerance = 1e-5;

/// A parsed calibration file.
struct Document {
  std::string file;
  CalibrationFormat format = CalibrationFormat::kOpenCvYaml;
  StorageNode root;

  [[noreturn]] void Fail(int line, const std::string& key, const std::string& what) const {
    throw FileError(file, line, key, what);
  }
  const StorageNode* Find(std::string_view key) const { return root.Find(key, file); }
  const StorageNode& Require(const std::string& key, const std::string& expected) const {
    const StorageNode* node = Find(key);
    if (node == nullptr) Fail(0, key, "missing key; expected " + expected);
    return *node;
  }
};

std::string ErrnoMessage(int error) { return std::generic_category().message(error); }

std::string ReadFileText(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw FileError(file, 0, "", "file not found");
  if (std::filesystem::is_directory(status)) {
    throw FileError(file, 0, "", "is a directory, expected a calibration file");
  }
  // A device (/dev/zero) or a pipe never ends: read regular files only, of a bounded size.
  if (!std::filesystem::is_regular_file(status)) {
    throw FileError(file, 0, "",
                    "not a regular file (a device or pipe), expected a calibration file");
  }
  if (const auto size = std::filesystem::file_size(path, ec);
      !ec && size > saccade::internal::kMaxConfigFileBytes) {
    throw FileError(
        file, 0, "",
        fmt::format("the file is {} bytes, more than the {} a calibration file may have", size,
                    saccade::internal::kMaxConfigFileBytes));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError(file, 0, "", "cannot be opened for reading");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw FileError(file, 0, "", "read error");
  if (text.find('\0') != std::string::npos) {
    throw FileError(file, 0, "", "binary content: expected a YAML or XML calibration file");
  }
  return text;
}

bool HasXmlExtension(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".xml";
}

bool LooksLikeXml(std::string_view text) {
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  const size_t first = text.find_first_not_of(" \t\r\n");
  return first != std::string_view::npos && text[first] == '<';
}

Document Load(const std::filesystem::path& path) {
  Document doc;
  doc.file = path.string();
  const std::string text = ReadFileText(path);
  if (HasXmlExtension(path) || LooksLikeXml(text)) {
    doc.format = CalibrationFormat::kOpenCvXml;
    doc.root = internal::ParseXmlStorage(text, doc.file);
  } else {
    doc.root = internal::ParseYamlStorage(text, doc.file);
    doc.format = doc.Find("distortion_model") != nullptr ? CalibrationFormat::kRosYaml
                                                         : CalibrationFormat::kOpenCvYaml;
  }
  return doc;
}

std::string Quote(std::string_view s) { return "'" + std::string(s) + "'"; }

const std::string& ScalarText(const Document& doc, const StorageNode& node, const std::string& key,
                              const std::string& expected) {
  if (node.kind != StorageNode::Kind::kScalar) {
    doc.Fail(node.line, key,
             "expected " + expected + ", got " +
                 (node.kind == StorageNode::Kind::kMap ? "a map" : "a sequence"));
  }
  return node.text;
}

int ParseInt(const Document& doc, const StorageNode& node, const std::string& key) {
  const std::string& text = ScalarText(doc, node, key, "an integer");
  std::string_view digits = text;
  if (digits.starts_with('+')) digits.remove_prefix(1);
  int value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size()) {
    doc.Fail(node.line, key, "expected an integer, got " + Quote(text));
  }
  return value;
}

// A finite real number; `is_float` reads it as OpenCV's dt 'f' (a float widened to double).
double ParseReal(const Document& doc, std::string_view text, int line, const std::string& key,
                 bool is_float) {
  std::string_view digits = text;
  if (digits.starts_with('+')) digits.remove_prefix(1);
  double value = 0.0;
  std::from_chars_result result{};
  if (is_float) {
    float f = 0.0F;
    result = std::from_chars(digits.data(), digits.data() + digits.size(), f);
    value = f;
  } else {
    result = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  }
  if (digits.empty() || result.ec == std::errc::invalid_argument ||
      result.ptr != digits.data() + digits.size()) {
    // FileStorage writes infinities and NaN as .Inf and .Nan.
    std::string lower(text);
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const bool special =
        lower.find("inf") != std::string::npos || lower.find("nan") != std::string::npos;
    doc.Fail(line, key,
             std::string(special ? "expected a finite number" : "expected a number") + ", got " +
                 Quote(text));
  }
  if (result.ec != std::errc() || !std::isfinite(value)) {
    doc.Fail(line, key, "expected a finite number, got " + Quote(text));
  }
  return value;
}

/// A matrix as stored: rows x cols values, row-major.
struct Matrix {
  int rows = 0;
  int cols = 0;
  std::vector<double> values;
  int line = 0;  ///< line of the key
  bool IsVector() const { return rows == 1 || cols == 1; }
  std::string Shape() const { return std::to_string(rows) + "x" + std::to_string(cols); }
};

// An OpenCV !!opencv-matrix (rows, cols, dt, data) or, with `require_dt` false, a ROS matrix
// (rows, cols, data).
Matrix ReadMatrix(const Document& doc, const StorageNode& node, const std::string& key,
                  bool require_dt) {
  const std::string expected =
      require_dt ? "an !!opencv-matrix with rows, cols, dt and data" : "rows, cols and data";
  Matrix m;
  m.line = node.key_line;
  if (node.kind != StorageNode::Kind::kMap) {
    doc.Fail(node.key_line, key,
             "expected a matrix (" + expected + "), got " +
                 (node.kind == StorageNode::Kind::kScalar ? "a scalar" : "a sequence"));
  }
  auto require = [&](const char* field) -> const StorageNode& {
    const StorageNode* child = node.Find(field, doc.file);
    if (child == nullptr) {
      doc.Fail(node.key_line, key + "." + field,
               "missing key; expected a matrix (" + expected + ")");
    }
    return *child;
  };
  const StorageNode& rows = require("rows");
  const StorageNode& cols = require("cols");
  m.rows = ParseInt(doc, rows, key + ".rows");
  m.cols = ParseInt(doc, cols, key + ".cols");
  if (m.rows < 0) doc.Fail(rows.line, key + ".rows", "expected a count >= 0, got " + rows.text);
  if (m.cols < 0) doc.Fail(cols.line, key + ".cols", "expected a count >= 0, got " + cols.text);
  bool is_float = false;
  const StorageNode* dt = require_dt ? &require("dt") : node.Find("dt", doc.file);
  if (dt != nullptr) {
    const std::string& type = ScalarText(doc, *dt, key + ".dt", "'d' or 'f'");
    if (type != "d" && type != "f") {
      doc.Fail(dt->line, key + ".dt", "expected 'd' (double) or 'f' (float), got " + Quote(type));
    }
    is_float = type == "f";
  }
  const StorageNode& data = require("data");
  const std::vector<internal::StorageToken> tokens =
      internal::Tokens(data, doc.file, key + ".data");
  const long long count = static_cast<long long>(m.rows) * m.cols;
  if (static_cast<long long>(tokens.size()) != count) {
    doc.Fail(data.line, key + ".data",
             "has " + std::to_string(tokens.size()) +
                 " values, expected rows * cols = " + m.Shape() + " = " + std::to_string(count));
  }
  m.values.reserve(tokens.size());
  for (size_t i = 0; i < tokens.size(); ++i) {
    m.values.push_back(ParseReal(doc, tokens[i].text, tokens[i].line,
                                 key + ".data[" + std::to_string(i) + "]", is_float));
  }
  return m;
}

// image_width and image_height of `doc`, std::nullopt if it has neither.
std::optional<ImageSize> FileImageSize(const Document& doc) {
  const StorageNode* width = doc.Find("image_width");
  const StorageNode* height = doc.Find("image_height");
  if (width == nullptr && height == nullptr) return std::nullopt;
  if (width == nullptr) {
    doc.Fail(0, "image_width",
             "missing key; the file has image_height (line " + std::to_string(height->key_line) +
                 ") but no image_width");
  }
  if (height == nullptr) {
    doc.Fail(0, "image_height",
             "missing key; the file has image_width (line " + std::to_string(width->key_line) +
                 ") but no image_height");
  }
  ImageSize size{ParseInt(doc, *width, "image_width"), ParseInt(doc, *height, "image_height")};
  if (size.width <= 0) {
    doc.Fail(width->line, "image_width", "expected a positive width in pixels, got " + width->text);
  }
  if (size.height <= 0) {
    doc.Fail(height->line, "image_height",
             "expected a positive height in pixels, got " + height->text);
  }
  return size;
}

// The image size from the file(s), else `fallback`, else a FileError naming image_width.
ImageSize ResolveImageSize(const Document& doc, const Document* other,
                           const std::optional<ImageSize>& fallback, const char* function) {
  if (auto size = FileImageSize(doc)) return *size;
  if (other != nullptr) {
    if (auto size = FileImageSize(*other)) return *size;
  }
  if (!fallback) {
    doc.Fail(0, "image_width",
             "missing key; the file stores no image size (image_width, image_height) and no "
             "size was given");
  }
  if (fallback->width <= 0 || fallback->height <= 0) {
    throw InvalidArgument(std::string(function) + ": size must be positive, got " +
                          std::to_string(fallback->width) + "x" + std::to_string(fallback->height));
  }
  return *fallback;
}

Intrinsics MakeIntrinsics(const Document& doc, const Matrix& K, const std::string& key,
                          const ImageSize& size) {
  if (K.rows != 3 || K.cols != 3) doc.Fail(K.line, key, "expected a 3x3 matrix, got " + K.Shape());
  Eigen::Matrix3d matrix;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) matrix(r, c) = K.values[static_cast<size_t>(3 * r + c)];
  }
  try {
    return Intrinsics::FromMatrix(matrix, size.width, size.height);
  } catch (const InvalidArgument& e) {
    doc.Fail(K.line, key, std::string("invalid camera matrix: ") + e.what());
  }
}

Distortion MakeDistortion(const Document& doc, const Matrix& D, const std::string& key,
                          DistortionModel model) {
  if (!D.IsVector() && !D.values.empty()) {
    doc.Fail(D.line, key, "expected a 1xN or Nx1 vector, got " + D.Shape());
  }
  try {
    return Distortion::FromCoefficients(model, D.values);
  } catch (const InvalidArgument& e) {
    doc.Fail(D.line, key, std::string("invalid distortion coefficients: ") + e.what());
  }
}

// fisheye_model (written by OpenCV's camera_calibration tutorial sample): 1 for fisheye.
bool ReadFisheyeFlag(const Document& doc) {
  const StorageNode* node = doc.Find("fisheye_model");
  if (node == nullptr) return false;
  const int value = ParseInt(doc, *node, "fisheye_model");
  if (value != 0 && value != 1) {
    doc.Fail(node->line, "fisheye_model",
             "expected 0 (radial-tangential) or 1 (fisheye), got " + node->text);
  }
  return value == 1;
}

std::string ReadName(const Document& doc) {
  const StorageNode* node = doc.Find("camera_name");
  return node == nullptr ? std::string() : ScalarText(doc, *node, "camera_name", "a string");
}

CameraModel ReadOpenCvCamera(const Document& doc, const std::string& k_key,
                             const std::string& d_key, const ImageSize& size, bool fisheye) {
  const Matrix K =
      ReadMatrix(doc, doc.Require(k_key, "the 3x3 camera matrix (!!opencv-matrix)"), k_key, true);
  const Matrix D = ReadMatrix(
      doc, doc.Require(d_key, "the distortion coefficients (!!opencv-matrix)"), d_key, true);
  const Intrinsics intrinsics = MakeIntrinsics(doc, K, k_key, size);
  return CameraModel(intrinsics, MakeDistortion(doc, D, d_key,
                                                fisheye ? DistortionModel::kFisheye
                                                        : DistortionModel::kRadialTangential));
}

CameraCalibration ReadOpenCvCameraFile(const Document& doc, const std::optional<ImageSize>& size) {
  if (doc.Find("camera_matrix") == nullptr && doc.Find("M1") != nullptr) {
    doc.Fail(0, "camera_matrix",
             "missing key; the file has M1 (a stereo calibration): read it with "
             "ReadStereoCalibration");
  }
  const ImageSize image_size = ResolveImageSize(doc, nullptr, size, "ReadCameraCalibration");
  CameraModel model = ReadOpenCvCamera(doc, "camera_matrix", "distortion_coefficients", image_size,
                                       ReadFisheyeFlag(doc));
  return {std::move(model), ReadName(doc)};
}

// ROS camera_info (camera_calibration_parsers' YAML).
CameraCalibration ReadRosCameraFile(const Document& doc, const std::optional<ImageSize>& size) {
  const ImageSize image_size = ResolveImageSize(doc, nullptr, size, "ReadCameraCalibration");
  const Matrix K =
      ReadMatrix(doc, doc.Require("camera_matrix", "the 3x3 camera matrix (rows, cols, data)"),
                 "camera_matrix", false);
  const StorageNode& model_node =
      doc.Require("distortion_model", "plumb_bob, rational_polynomial or equidistant");
  const std::string& model_name = ScalarText(doc, model_node, "distortion_model", "a model name");
  const StorageNode* d_node = doc.Find("distortion_coefficients");
  Matrix D;
  if (d_node != nullptr) {
    D = ReadMatrix(doc, *d_node, "distortion_coefficients", false);
  } else if (!model_name.empty() && model_name != "none") {
    doc.Fail(0, "distortion_coefficients",
             "missing key; expected the coefficients of the " + model_name + " model");
  }
  const size_t count = D.values.size();
  DistortionModel model = DistortionModel::kRadialTangential;
  if (model_name == "plumb_bob") {
    if (count != 4 && count != 5) {
      doc.Fail(D.line, "distortion_coefficients",
               "plumb_bob has 5 coefficients (k1 k2 p1 p2 k3), got " + std::to_string(count));
    }
  } else if (model_name == "rational_polynomial") {
    if (count < 8) {
      doc.Fail(D.line, "distortion_coefficients",
               "rational_polynomial has 8 coefficients (k1 k2 p1 p2 k3 k4 k5 k6), got " +
                   std::to_string(count));
    }
  } else if (model_name == "equidistant") {
    model = DistortionModel::kFisheye;
  } else if (model_name.empty() || model_name == "none") {
    model = DistortionModel::kNone;
  } else {
    doc.Fail(model_node.line, "distortion_model",
             "unknown model " + Quote(model_name) +
                 "; expected plumb_bob, rational_polynomial, equidistant or none");
  }
  const Intrinsics intrinsics = MakeIntrinsics(doc, K, "camera_matrix", image_size);
  return {CameraModel(intrinsics, MakeDistortion(doc, D, "distortion_coefficients", model)),
          ReadName(doc)};
}

// ---------------------------------------------------------------------------------------
// Writing.

void CheckName(const std::string& name, const char* function) {
  for (char c : name) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) {
      throw InvalidArgument(std::string(function) +
                            ": the camera name must not contain control characters, got " +
                            Quote(name));
    }
  }
}

// The coefficients OpenCV would write: radtan 5 (8 when k4..k6 are not zero), fisheye 4;
// no distortion is written as 5 zeros, since neither OpenCV nor ROS files name that model.
std::vector<double> FileCoefficients(const Distortion& distortion) {
  switch (distortion.model()) {
    case DistortionModel::kNone:
      return std::vector<double>(5, 0.0);
    case DistortionModel::kFisheye:
      return distortion.coefficients();
    case DistortionModel::kRadialTangential: {
      std::vector<double> c = distortion.coefficients();
      const bool rational = std::any_of(c.begin() + 5, c.end(), [](double v) { return v != 0.0; });
      c.resize(rational ? 8 : 5);
      return c;
    }
  }
  return {};
}

std::vector<double> RowMajor(const Eigen::Matrix3d& m) {
  std::vector<double> v;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) v.push_back(m(r, c));
  }
  return v;
}

void WriteCamera(internal::OpenCvStorageWriter* writer, const CameraModel& camera,
                 const std::string& k_key, const std::string& d_key) {
  writer->WriteMatrix(k_key, 3, 3, RowMajor(camera.intrinsics().Matrix()));
  const std::vector<double> d = FileCoefficients(camera.distortion());
  writer->WriteMatrix(d_key, 1, static_cast<int>(d.size()), d);
}

bool IsOpenCvFormat(CalibrationFormat format) {
  return format == CalibrationFormat::kOpenCvYaml || format == CalibrationFormat::kOpenCvXml;
}

std::string OpenCvCameraText(const CameraCalibration& calibration, bool xml) {
  const CameraModel& camera = calibration.model;
  internal::OpenCvStorageWriter writer(xml);
  writer.WriteInt("image_width", camera.intrinsics().width());
  writer.WriteInt("image_height", camera.intrinsics().height());
  if (!calibration.name.empty()) writer.WriteString("camera_name", calibration.name);
  writer.WriteInt("fisheye_model", camera.distortion().model() == DistortionModel::kFisheye);
  WriteCamera(&writer, camera, "camera_matrix", "distortion_coefficients");
  return writer.Finish();
}

std::string RosList(const std::vector<double>& values) {
  std::string out = "[";
  for (size_t i = 0; i < values.size(); ++i) {
    if (i > 0) out += ", ";
    out += internal::FormatDouble(values[i]);
  }
  return out + "]";
}

std::string RosMatrix(const char* key, int rows, int cols, const std::vector<double>& values) {
  return std::string(key) + ":\n  rows: " + std::to_string(rows) +
         "\n  cols: " + std::to_string(cols) + "\n  data: " + RosList(values) + "\n";
}

// The layout of camera_calibration_parsers' writeCalibrationYml.
std::string RosCameraText(const CameraCalibration& calibration) {
  const Intrinsics& intrinsics = calibration.model.intrinsics();
  const Distortion& distortion = calibration.model.distortion();
  const std::vector<double> d = FileCoefficients(distortion);
  const char* model = "plumb_bob";
  if (distortion.model() == DistortionModel::kFisheye) {
    model = "equidistant";
  } else if (d.size() == 8) {
    model = "rational_polynomial";
  }
  const std::vector<double> K = RowMajor(intrinsics.Matrix());
  // A monocular camera: no rectification, P = [K | 0].
  const std::vector<double> rectification = RowMajor(Eigen::Matrix3d::Identity());
  const std::vector<double> P = {K[0], K[1], K[2], 0.0,  K[3], K[4],
                                 K[5], 0.0,  K[6], K[7], K[8], 0.0};
  std::string out;
  out += "image_width: " + std::to_string(intrinsics.width()) + "\n";
  out += "image_height: " + std::to_string(intrinsics.height()) + "\n";
  out += "camera_name: " + internal::YamlQuoted(calibration.name) + "\n";
  out += RosMatrix("camera_matrix", 3, 3, K);
  out += std::string("distortion_model: ") + model + "\n";
  out += RosMatrix("distortion_coefficients", 1, static_cast<int>(d.size()), d);
  out += RosMatrix("rectification_matrix", 3, 3, rectification);
  out += RosMatrix("projection_matrix", 3, 4, P);
  return out;
}

// Writes `content` to a new file beside `path` and renames it over `path`: readers never see
// a half-written file, and a failure leaves nothing behind.
void WriteFileAtomically(const std::filesystem::path& path, const std::string& content) {
  const std::string file = path.string();
  if (!path.has_filename()) throw FileError(file, 0, "", "expected a file name, got a directory");
  const std::filesystem::path directory =
      path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  static std::atomic<unsigned> counter{0};
  std::filesystem::path temporary;
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    temporary = TemporaryPathFor(directory / path.filename(), counter++);
    fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) {
      throw FileError(
          file, 0, "",
          "cannot create a temporary file in " + directory.string() + ": " + ErrnoMessage(errno));
    }
  }
  if (fd < 0) throw FileError(file, 0, "", "cannot create a unique temporary file");
  auto fail = [&](const std::string& what, int error) {
    ::close(fd);
    ::unlink(temporary.c_str());
    throw FileError(file, 0, "", what + ": " + ErrnoMessage(error));
  };
  size_t written = 0;
  while (written < content.size()) {
    const ssize_t n = ::write(fd, content.data() + written, content.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail("write failed", errno);
    written += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0) fail("write failed", errno);
  if (::close(fd) != 0) {
    const int error = errno;
    ::unlink(temporary.c_str());
    throw FileError(file, 0, "", "write failed: " + ErrnoMessage(error));
  }
  if (::rename(temporary.c_str(), path.c_str()) != 0) {
    const int error = errno;
    ::unlink(temporary.c_str());
    throw FileError(file, 0, "", "cannot replace the file: " + ErrnoMessage(error));
  }
}

bool IsRotation(const Eigen::Matrix3d& R) {
  return R.allFinite() &&
         (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <=
             kRotationTolerance &&
         R.determinant() > 0.0;
}

}  // namespace

bool IsStereoCalibrationFile(const std::filesystem::path& path) {
  const Document doc = Load(path);
  return doc.format != CalibrationFormat::kRosYaml && doc.Find("M1") != nullptr &&
         doc.Find("camera_matrix") == nullptr;
}

bool HasStereoExtrinsics(const std::filesystem::path& path) {
  const Document doc = Load(path);
  return doc.Find("R") != nullptr && doc.Find("T") != nullptr;
}

namespace {

// A ROS camera_info's rows x cols matrix `key`, required.
Eigen::MatrixXd RosMatrixOf(const Document& doc, const std::string& key, int rows, int cols,
                            const std::string& expected) {
  const Matrix m = ReadMatrix(doc, doc.Require(key, expected), key, false);
  if (m.rows != rows || m.cols != cols) {
    doc.Fail(m.line, key,
             "expected a " + std::to_string(rows) + "x" + std::to_string(cols) + " matrix, got " +
                 m.Shape());
  }
  Eigen::MatrixXd out(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) out(r, c) = m.values[static_cast<size_t>(cols * r + c)];
  }
  return out;
}

}  // namespace

StereoCalibration ReadRosStereoPair(const std::filesystem::path& left,
                                    const std::filesystem::path& right,
                                    std::optional<ImageSize> size) {
  const Document docs[2] = {Load(left), Load(right)};
  Eigen::Matrix3d rect[2];
  Eigen::Matrix<double, 3, 4> P[2];
  std::vector<CameraModel> models;
  for (int i = 0; i < 2; ++i) {
    const Document& doc = docs[i];
    if (doc.format != CalibrationFormat::kRosYaml) {
      doc.Fail(0, "distortion_model",
               "missing key; expected a ROS camera_info file (the " +
                   std::string(i == 0 ? "left" : "right") + " camera of a ROS stereo pair)");
    }
    models.push_back(ReadRosCameraFile(doc, size).model);
    rect[i] = RosMatrixOf(doc, "rectification_matrix", 3, 3,
                          "the 3x3 rectification matrix of a stereo camera (rows, cols, data)");
    if (!IsRotation(rect[i])) {
      doc.Fail(doc.Require("rectification_matrix", "").key_line, "rectification_matrix",
               "not a rotation matrix (expected R^T R = I and det R = 1)");
    }
    P[i] = RosMatrixOf(doc, "projection_matrix", 3, 4,
                       "the 3x4 projection matrix of a stereo camera (rows, cols, data)");
    if (!(P[i](0, 0) > 0.0) || !(P[i](1, 1) > 0.0)) {
      doc.Fail(doc.Require("projection_matrix", "").key_line, "projection_matrix",
               "expected fx' = P[0][0] > 0 and fy' = P[1][1] > 0");
    }
  }
  // The rectified right camera sits at t' in the rectified left camera's frame (negated):
  // P2 = K' [I | t'] with K' shared, as cv::stereoRectify writes it.
  const Eigen::Vector3d t((P[1](0, 3) - P[0](0, 3)) / P[1](0, 0),
                          (P[1](1, 3) - P[0](1, 3)) / P[1](1, 1), 0.0);
  if (t.norm() == 0.0) {
    docs[1].Fail(docs[1].Require("projection_matrix", "").key_line, "projection_matrix",
                 "no baseline (P[0][3] and P[1][3] equal the left camera's): not the right "
                 "camera of a calibrated stereo pair; expected P[0][3] = -fx' * baseline");
  }
  StereoCalibration stereo{models[0], models[1]};
  stereo.R = rect[1].transpose() * rect[0];
  stereo.T = rect[1].transpose() * t;
  return stereo;
}

CalibrationFormat DetectCalibrationFormat(const std::filesystem::path& path) {
  return Load(path).format;
}

std::optional<ImageSize> ReadCalibrationImageSize(const std::filesystem::path& path) {
  return FileImageSize(Load(path));
}

CameraCalibration ReadCameraCalibration(const std::filesystem::path& path,
                                        std::optional<ImageSize> size) {
  const Document doc = Load(path);
  return doc.format == CalibrationFormat::kRosYaml ? ReadRosCameraFile(doc, size)
                                                   : ReadOpenCvCameraFile(doc, size);
}

void WriteCameraCalibration(const CameraCalibration& calibration, const std::filesystem::path& path,
                            CalibrationFormat format) {
  CheckName(calibration.name, "WriteCameraCalibration");
  WriteFileAtomically(path,
                      format == CalibrationFormat::kRosYaml
                          ? RosCameraText(calibration)
                          : OpenCvCameraText(calibration, format == CalibrationFormat::kOpenCvXml));
}

StereoCalibration ReadStereoCalibration(const std::filesystem::path& path,
                                        const std::optional<std::filesystem::path>& extrinsics_path,
                                        std::optional<ImageSize> size) {
  const Document intrinsics = Load(path);
  std::optional<Document> extrinsics;
  if (extrinsics_path) extrinsics = Load(*extrinsics_path);
  const Document& pose = extrinsics ? *extrinsics : intrinsics;

  const ImageSize image_size = ResolveImageSize(intrinsics, extrinsics ? &*extrinsics : nullptr,
                                                size, "ReadStereoCalibration");
  const bool fisheye = ReadFisheyeFlag(intrinsics);
  StereoCalibration stereo{ReadOpenCvCamera(intrinsics, "M1", "D1", image_size, fisheye),
                           ReadOpenCvCamera(intrinsics, "M2", "D2", image_size, fisheye)};

  const Matrix R =
      ReadMatrix(pose, pose.Require("R", "the 3x3 rotation matrix (!!opencv-matrix)"), "R", true);
  if (R.rows != 3 || R.cols != 3) pose.Fail(R.line, "R", "expected a 3x3 matrix, got " + R.Shape());
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) stereo.R(r, c) = R.values[static_cast<size_t>(3 * r + c)];
  }
  if (!IsRotation(stereo.R)) {
    pose.Fail(R.line, "R", "not a rotation matrix (expected R^T R = I and det R = 1)");
  }
  const Matrix T =
      ReadMatrix(pose, pose.Require("T", "the translation 3-vector (!!opencv-matrix)"), "T", true);
  if (!T.IsVector() || T.values.size() != 3) {
    pose.Fail(T.line, "T", "expected a 3x1 or 1x3 vector, got " + T.Shape());
  }
  stereo.T = Eigen::Vector3d(T.values[0], T.values[1], T.values[2]);
  return stereo;
}

CameraCalibration ReadStereoCameraCalibration(const std::filesystem::path& path, int index,
                                              std::optional<ImageSize> size) {
  if (index != 1 && index != 2) {
    throw InvalidArgument(
        "ReadStereoCameraCalibration: index must be 1 (M1 D1) or 2 (M2 D2), got " +
        std::to_string(index));
  }
  const Document doc = Load(path);
  const std::string k_key = index == 1 ? "M1" : "M2";
  const std::string d_key = index == 1 ? "D1" : "D2";
  if (doc.Find(k_key) == nullptr && doc.Find("camera_matrix") != nullptr) {
    doc.Fail(0, k_key,
             "missing key; the file has camera_matrix (one camera): read it with "
             "ReadCameraCalibration");
  }
  const ImageSize image_size = ResolveImageSize(doc, nullptr, size, "ReadStereoCameraCalibration");
  return {ReadOpenCvCamera(doc, k_key, d_key, image_size, ReadFisheyeFlag(doc)), std::string()};
}

void WriteStereoCalibration(const StereoCalibration& calibration, const std::filesystem::path& path,
                            CalibrationFormat format) {
  if (!IsOpenCvFormat(format)) {
    throw InvalidArgument(
        "WriteStereoCalibration: a ROS camera_info file holds one camera; write OpenCV YAML or "
        "XML, or each camera with WriteCameraCalibration");
  }
  const Intrinsics& left = calibration.left.intrinsics();
  const Intrinsics& right = calibration.right.intrinsics();
  if (left.width() != right.width() || left.height() != right.height()) {
    throw InvalidArgument("WriteStereoCalibration: the file stores one image size, got " +
                          std::to_string(left.width()) + "x" + std::to_string(left.height()) +
                          " (left) and " + std::to_string(right.width()) + "x" +
                          std::to_string(right.height()) + " (right)");
  }
  const bool fisheye = calibration.left.distortion().model() == DistortionModel::kFisheye;
  if (fisheye != (calibration.right.distortion().model() == DistortionModel::kFisheye)) {
    throw InvalidArgument(
        "WriteStereoCalibration: the file stores one fisheye_model flag, got one fisheye and one "
        "radial-tangential camera");
  }
  if (!IsRotation(calibration.R)) {
    throw InvalidArgument("WriteStereoCalibration: R is not a rotation matrix");
  }
  if (!calibration.T.allFinite()) {
    throw InvalidArgument("WriteStereoCalibration: T has a non-finite value");
  }
  internal::OpenCvStorageWriter writer(format == CalibrationFormat::kOpenCvXml);
  writer.WriteInt("image_width", left.width());
  writer.WriteInt("image_height", left.height());
  writer.WriteInt("fisheye_model", fisheye);
  WriteCamera(&writer, calibration.left, "M1", "D1");
  WriteCamera(&writer, calibration.right, "M2", "D2");
  writer.WriteMatrix("R", 3, 3, RowMajor(calibration.R));
  const std::vector<double> T = {calibration.T.x(), calibration.T.y(), calibration.T.z()};
  writer.WriteMatrix("T", 3, 1, T);
  WriteFileAtomically(path, writer.Finish());
}

}  // namespace saccade::geometry
