#include "saccade/render/emva_files.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <regex>

#include "saccade/core/error.h"
#include "saccade/core/image_io.h"

namespace saccade::render {
namespace {

namespace fs = std::filesystem;

// The files of one exposure, by frame index.
struct ExposureFiles {
  std::string label;  // as written in the names, microseconds
  double exposure_s = 0.0;
  std::map<int, fs::path> dark;
  std::map<int, fs::path> flat;
};

std::map<double, ExposureFiles> ListSeries(const fs::path& folder) {
  if (!fs::is_directory(folder)) {
    throw FileError(folder.string(), 0, "", "expected a folder of dark_*/flat_* PNG files");
  }
  static const std::regex kName(R"(^(dark|flat)_([0-9]+(?:\.[0-9]+)?)_([0-9]+)\.png$)");
  std::map<double, ExposureFiles> series;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    std::smatch m;
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file() || !std::regex_match(name, m, kName)) continue;
    const double us = std::stod(m[2].str());
    ExposureFiles& files = series[us];
    if (!files.label.empty() && files.label != m[2].str()) {
      throw FileError(entry.path().string(), 0, "",
                      fmt::format("exposure written as '{}' and as '{}' elsewhere: one name an "
                                  "exposure",
                                  m[2].str(), files.label));
    }
    files.label = m[2].str();
    files.exposure_s = us * 1e-6;
    const int index = std::stoi(m[3].str());
    (m[1].str() == "dark" ? files.dark : files.flat)[index] = entry.path();
  }
  return series;
}

std::map<std::string, double> ReadPhotons(const fs::path& csv) {
  std::ifstream in(csv);
  if (!in) throw FileError(csv.string(), 0, "", "cannot open the photon counts (CSV)");
  std::map<std::string, double> photons;
  static const std::regex kLine(R"(^\s*([0-9]+(?:\.[0-9]+)?)\s*,\s*([0-9eE+.\-]+)\s*$)");
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.empty() || line[0] == '#' || (n == 1 && line.find("exposure") != std::string::npos)) {
      continue;
    }
    std::smatch m;
    double value = 0.0;
    bool ok = std::regex_match(line, m, kLine);
    if (ok) {
      try {
        value = std::stod(m[2].str());
      } catch (const std::exception&) {
        ok = false;
      }
    }
    if (!ok || !(value >= 0.0) || !std::isfinite(value)) {
      throw FileError(csv.string(), n, "",
                      fmt::format("expected 'exposure_us,photons' (photons >= 0), got '{}'", line));
    }
    photons[std::to_string(std::stod(m[1].str()))] = value;
  }
  return photons;
}

// Reads one frame, checking its size against the first's.
Plane ReadFrame(const fs::path& path, int channel, std::optional<std::pair<int, int>>& size) {
  const Plane plane = PlaneFromImage(ReadImage(path), channel);
  if (!size) size = std::make_pair(plane.width, plane.height);
  if (plane.width != size->first || plane.height != size->second) {
    throw FileError(path.string(), 0, "",
                    fmt::format("a {} x {} frame among frames of {} x {}", plane.width,
                                plane.height, size->first, size->second));
  }
  return plane;
}

void CheckPairs(const fs::path& folder, const ExposureFiles& files) {
  for (const char* kind : {"dark", "flat"}) {
    const auto& frames = kind[0] == 'd' ? files.dark : files.flat;
    for (const int k : {0, 1}) {
      if (frames.count(k) == 0) {
        throw FileError((folder / fmt::format("{}_{}_{}.png", kind, files.label, k)).string(), 0,
                        "",
                        fmt::format("missing: exposure {} us needs the pairs dark_{}_0/1.png and "
                                    "flat_{}_0/1.png",
                                    files.label, files.label, files.label));
      }
    }
  }
}

StackStats ReadStack(const std::map<int, fs::path>& frames, int channel,
                     std::optional<std::pair<int, int>>& size) {
  std::vector<Plane> planes;
  for (const auto& [k, path] : frames) planes.push_back(ReadFrame(path, channel, size));
  return MeasureStack(planes);
}

}  // namespace

std::string EmvaFileName(const std::string& kind, double exposure_s, int index) {
  std::string us = fmt::format("{:.3f}", exposure_s * 1e6);
  while (us.back() == '0') us.pop_back();
  if (us.back() == '.') us.pop_back();
  return fmt::format("{}_{}_{}.png", kind, us, index);
}

EmvaResult MeasureImageFiles(const fs::path& folder, const fs::path& photons_csv, int channel) {
  const std::map<double, ExposureFiles> series = ListSeries(folder);
  if (static_cast<int>(series.size()) < kMinEmvaPoints) {
    throw FileError(folder.string(), 0, "",
                    fmt::format("{} exposure(s) of dark_<exposure_us>_<k>.png / flat_... files; "
                                "the series needs at least {}",
                                series.size(), kMinEmvaPoints));
  }
  std::map<std::string, double> photons;
  if (!photons_csv.empty()) photons = ReadPhotons(photons_csv);
  std::optional<std::pair<int, int>> size;
  std::vector<EmvaPoint> points;
  for (const auto& [us, files] : series) {
    CheckPairs(folder, files);
    EmvaPoint p;
    p.exposure_s = files.exposure_s;
    if (!photons_csv.empty()) {
      const auto it = photons.find(std::to_string(us));
      if (it == photons.end()) {
        throw FileError(photons_csv.string(), 0, "",
                        fmt::format("no photon count for exposure {} us", files.label));
      }
      p.photons = it->second;
    }
    p.dark = MeasurePair(ReadFrame(files.dark.at(0), channel, size),
                         ReadFrame(files.dark.at(1), channel, size));
    p.bright = MeasurePair(ReadFrame(files.flat.at(0), channel, size),
                           ReadFrame(files.flat.at(1), channel, size));
    points.push_back(p);
  }
  // The stacks: the most frames of both kinds; of those, the flat nearest half the largest
  // signal (about 50 % of saturation).
  double top = 0.0;
  for (const EmvaPoint& p : points) top = std::max(top, p.bright.mean - p.dark.mean);
  const ExposureFiles* stack = nullptr;
  std::size_t most = 0;
  double distance = 0.0;
  std::size_t i = 0;
  for (const auto& [us, files] : series) {
    const std::size_t count = std::min(files.dark.size(), files.flat.size());
    const double d = std::abs(points[i++].bright.mean - points[0].dark.mean - 0.5 * top);
    if (count > most || (count == most && d < distance)) {
      stack = &files;
      most = count;
      distance = d;
    }
  }
  const StackStats dark = ReadStack(stack->dark, channel, size);
  const StackStats bright = ReadStack(stack->flat, channel, size);
  return EvaluateEmva(std::move(points), dark, bright);
}

}  // namespace saccade::render
