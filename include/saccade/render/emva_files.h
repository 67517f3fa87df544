#pragma once
// An EMVA 1288 series as image files, so that `saccade emva --images DIR` measures a real
// camera (and `--write-images DIR` writes the simulated one the same way).
//
// Naming, in one folder: `dark_<exposure_us>_<k>.png` and `flat_<exposure_us>_<k>.png`, with
// <exposure_us> the exposure in microseconds (a decimal number, "1000" or "1000.5") and <k>
// the frame's index at that exposure, 0, 1, ...: frames 0 and 1 are the pair of the photon
// transfer curve; the exposure with the most frames of both kinds (at least 2; of those, the
// one nearest 50 % of saturation) gives the nonuniformity stacks. PNG of 8 or 16 bits, gray or
// colour (`channel` picks one), values as stored (a 12-bit camera's DN shifted into 16 bits
// scale K by 16). Other files are ignored.
// Photon counts, optional (for the quantum efficiency): a CSV of lines `exposure_us,photons`
// (mean photons a pixel collects at that exposure); '#' comments and a header line allowed.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "saccade/render/emva_measurement.h"

namespace saccade::render {

/// "dark_<exposure_us>_<index>.png" for `kind` "dark" or "flat" (exposure printed with
/// up to 3 decimals, trailing zeros dropped).
std::string EmvaFileName(const std::string& kind, double exposure_s, int index);

/// Measures the series in `folder` (see above); `photons_csv` empty: no photon counts.
/// Throws FileError or InvalidArgument naming the file and what is wrong: no such folder, an
/// exposure without both pairs, frames of different sizes, fewer than kMinEmvaPoints
/// exposures, an exposure missing from the CSV, a bad CSV line, or EvaluateEmva's errors.
EmvaResult MeasureImageFiles(const std::filesystem::path& folder,
                             const std::filesystem::path& photons_csv, int channel);

}  // namespace saccade::render
