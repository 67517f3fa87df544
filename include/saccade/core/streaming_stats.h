#pragma once
// Summaries of long runs in constant memory: count, mean, min and max exactly, quantiles
// (median, p95, ...) from a histogram of logarithmic bins. A run of 100,000 steps or of hours
// keeps the same few kilobytes per series, not every sample.
//
// Accuracy: a quantile is the nearest-rank sample's bin, reported at the bin's geometric centre
// and clamped to [min, max], so it is within kRelativeError of the exact nearest-rank quantile
// for samples in [kMinValue, kMaxValue] (samples below kMinValue count as 0; above kMaxValue
// as kMaxValue, and max() stays exact).
#include <cstdint>
#include <vector>

namespace saccade {

class StreamingStats {
 public:
  /// Bins grow by this ratio: a bin's centre is within sqrt(kGrowth) - 1 of any sample in it.
  static constexpr double kGrowth = 1.02;
  static constexpr double kRelativeError = 0.00995;  ///< sqrt(1.02) - 1, rounded up
  static constexpr double kMinValue = 1e-9;          ///< e.g. a nanosecond, in seconds
  static constexpr double kMaxValue = 1e6;           ///< e.g. 11.6 days, in seconds

  StreamingStats();

  /// Adds a sample (finite, >= 0; others are ignored and counted in rejected()).
  void Add(double value);

  int64_t count() const { return count_; }
  int64_t rejected() const { return rejected_; }
  /// 0 when empty.
  double mean() const { return count_ ? sum_ / static_cast<double>(count_) : 0.0; }
  double min() const { return count_ ? min_ : 0.0; }
  double max() const { return count_ ? max_ : 0.0; }
  /// The nearest-rank q-quantile, q in [0, 1] (0.5: the median, 0.95: p95); 0 when empty.
  double Quantile(double q) const;

  /// Bytes held, the same for 10 samples and 10 million.
  std::size_t memory_bytes() const { return sizeof(*this) + bins_.capacity() * sizeof(int64_t); }

 private:
  std::vector<int64_t> bins_;  // [0]: below kMinValue; then logarithmic bins
  int64_t count_ = 0;
  int64_t rejected_ = 0;
  double sum_ = 0.0;
  double min_ = 0.0;
  double max_ = 0.0;
};

}  // namespace saccade
