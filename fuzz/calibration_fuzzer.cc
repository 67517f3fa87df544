// libFuzzer target: calibration files (geometry/calibration_io.h): OpenCV FileStorage YAML
// and XML, ROS CameraInfo YAML, one camera or a stereo pair. The first input byte picks the
// file's extension (.yml, .xml or .yaml: the readers detect the format from it and from the
// content); the rest is the file. Bad input must end in a saccade::Error (a FileError naming
// file, line and key); anything else escaping is a bug. What reads must survive the round
// trip: written again in each of the three formats and read back, it is the same camera (K,
// size, name; the distortion the same, "none" coming back as zero radial-tangential), and
// a stereo file written again as OpenCV YAML and XML reads back the same R and T. Built and
// run by fuzz/run.sh.
//
// The files live in a folder of their own ($TMPDIR or /tmp, per process), since the readers
// and writers take paths.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "saccade/core/error.h"
#include "saccade/geometry/calibration_io.h"

namespace fs = std::filesystem;
namespace geo = saccade::geometry;

namespace {

constexpr std::size_t kMaxInput = 16 * 1024;

void Check(bool condition) {
  if (!condition) std::abort();  // libFuzzer reports it with the input
}

const fs::path& Dir() {
  static const fs::path dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    fs::path d = fs::path(tmp != nullptr ? tmp : "/tmp") /
                 ("saccade-calibration-fuzz-" + std::to_string(getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

void CheckSameCamera(const geo::CameraModel& a, const geo::CameraModel& b) {
  Check(a.intrinsics() == b.intrinsics());
  if (a.distortion().model() == geo::DistortionModel::kNone) {
    Check(b.distortion().IsIdentity());
  } else {
    Check(a.distortion() == b.distortion());
  }
}

// Written in every format and read back: the same camera.
void CheckCameraRoundTrip(const geo::CameraCalibration& calibration) {
  const struct {
    geo::CalibrationFormat format;
    const char* name;
  } formats[] = {{geo::CalibrationFormat::kOpenCvYaml, "again.yml"},
                 {geo::CalibrationFormat::kOpenCvXml, "again.xml"},
                 {geo::CalibrationFormat::kRosYaml, "again.yaml"}};
  for (const auto& f : formats) {
    const fs::path path = Dir() / f.name;
    try {
      geo::WriteCameraCalibration(calibration, path, f.format);
    } catch (const saccade::InvalidArgument&) {
      continue;  // a name with control characters is not written (documented)
    }
    const geo::CameraCalibration back = geo::ReadCameraCalibration(path);
    CheckSameCamera(calibration.model, back.model);
    Check(back.name == calibration.name);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  if (size < 1 || size > kMaxInput) return 0;
  static const char* const kExtensions[] = {".yml", ".xml", ".yaml"};
  const fs::path path = Dir() / (std::string("fuzz") + kExtensions[data[0] % 3]);
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
    Check(static_cast<bool>(out));
  }
  const geo::ImageSize fallback{640, 480};
  try {
    (void)geo::ReadCalibrationImageSize(path);
  } catch (const saccade::Error&) {
  }
  // Read inside try (bad input is rejected), round trips outside it (must not throw).
  const auto read = [](auto&& reader) -> std::optional<geo::CameraCalibration> {
    try {
      return reader();
    } catch (const saccade::Error&) {
      return std::nullopt;
    }
  };
  if (auto c = read([&] { return geo::ReadCameraCalibration(path, fallback); })) {
    CheckCameraRoundTrip(*c);
  }
  for (const int index : {1, 2}) {
    if (auto c = read([&] { return geo::ReadStereoCameraCalibration(path, index, fallback); })) {
      CheckCameraRoundTrip(*c);
    }
  }
  std::optional<geo::StereoCalibration> stereo;
  try {
    stereo = geo::ReadStereoCalibration(path, std::nullopt, fallback);
  } catch (const saccade::Error&) {
  }
  if (stereo) {
    for (const auto format :
         {geo::CalibrationFormat::kOpenCvYaml, geo::CalibrationFormat::kOpenCvXml}) {
      const fs::path again =
          Dir() / (format == geo::CalibrationFormat::kOpenCvXml ? "stereo.xml" : "stereo.yml");
      try {
        geo::WriteStereoCalibration(*stereo, again, format);
      } catch (const saccade::InvalidArgument&) {
        continue;  // two sizes or two models in one file, R not a rotation: not writable
      }
      const geo::StereoCalibration back = geo::ReadStereoCalibration(again);
      CheckSameCamera(stereo->left, back.left);
      CheckSameCamera(stereo->right, back.right);
      Check(back.R == stereo->R && back.T == stereo->T);
    }
  }
  return 0;
}
