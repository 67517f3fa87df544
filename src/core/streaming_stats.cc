#include "saccade/core/streaming_stats.h"

#include <algorithm>
#include <cmath>

namespace saccade {
namespace {

const double kLogGrowth = std::log(StreamingStats::kGrowth);
// Bins of [kMinValue * g^i, kMinValue * g^(i+1)), i = 0 .. kBins - 1, past the zero bin.
const int kBins =
    static_cast<int>(
        std::ceil(std::log(StreamingStats::kMaxValue / StreamingStats::kMinValue) / kLogGrowth)) +
    1;

}  // namespace

StreamingStats::StreamingStats() : bins_(static_cast<std::size_t>(kBins) + 1, 0) {}

void StreamingStats::Add(double value) {
  if (!std::isfinite(value) || value < 0.0) {
    ++rejected_;
    return;
  }
  std::size_t bin = 0;
  if (value >= kMinValue) {
    const double index = std::floor(std::log(value / kMinValue) / kLogGrowth);
    bin = 1 + static_cast<std::size_t>(std::clamp(index, 0.0, static_cast<double>(kBins - 1)));
  }
  ++bins_[bin];
  min_ = count_ ? std::min(min_, value) : value;
  max_ = count_ ? std::max(max_, value) : value;
  sum_ += value;
  ++count_;
}

double StreamingStats::Quantile(double q) const {
  if (count_ == 0) return 0.0;
  q = std::clamp(q, 0.0, 1.0);
  // Nearest rank: the smallest sample with at least q * n samples at or below it.
  const auto rank = std::max<int64_t>(1, static_cast<int64_t>(std::ceil(q * count_)));
  int64_t seen = 0;
  for (std::size_t bin = 0; bin < bins_.size(); ++bin) {
    seen += bins_[bin];
    if (seen < rank) continue;
    if (bin == 0) return std::clamp(0.0, min_, max_);
    const double centre = kMinValue * std::exp((static_cast<double>(bin - 1) + 0.5) * kLogGrowth);
    return std::clamp(centre, min_, max_);
  }
  return max_;
}

}  // namespace saccade
