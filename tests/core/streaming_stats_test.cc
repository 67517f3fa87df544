#include "saccade/core/streaming_stats.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace saccade {
namespace {

// The exact nearest-rank q-quantile of `v`.
double Exact(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const auto rank = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(q * v.size())));
  return v[rank - 1];
}

TEST(StreamingStatsTest, QuantilesAreWithinTheStatedRelativeErrorOfTheExactOnes) {
  // Step times as a loop has them: log-normal around 10 ms, a tail of slow steps (fixed seed).
  std::mt19937_64 engine(20261124);
  std::lognormal_distribution<double> step(std::log(0.010), 0.6);
  std::uniform_real_distribution<double> tail(0.1, 2.0);
  std::vector<double> samples;
  StreamingStats stats;
  for (int i = 0; i < 200000; ++i) {
    const double s = i % 97 == 0 ? tail(engine) : step(engine);
    samples.push_back(s);
    stats.Add(s);
  }
  for (double q : {0.0, 0.01, 0.25, 0.5, 0.9, 0.95, 0.99, 0.999, 1.0}) {
    const double exact = Exact(samples, q);
    EXPECT_LE(std::abs(stats.Quantile(q) - exact), StreamingStats::kRelativeError * exact)
        << "q = " << q << ": " << stats.Quantile(q) << " vs " << exact;
  }
  double sum = 0.0;
  for (double s : samples) sum += s;
  EXPECT_EQ(stats.count(), 200000);
  EXPECT_NEAR(stats.mean(), sum / samples.size(), 1e-12);
  EXPECT_EQ(stats.max(), *std::max_element(samples.begin(), samples.end()));
  EXPECT_EQ(stats.min(), *std::min_element(samples.begin(), samples.end()));
}

TEST(StreamingStatsTest, MemoryDoesNotGrowWithTheNumberOfSamples) {
  StreamingStats few, many;
  for (int i = 0; i < 10; ++i) few.Add(0.001 * i);
  for (int i = 0; i < 1000000; ++i) many.Add(1e-6 * (i % 5000 + 1));
  EXPECT_EQ(few.memory_bytes(), many.memory_bytes());
  EXPECT_LT(many.memory_bytes(), 16 * 1024u);
}

TEST(StreamingStatsTest, EdgesZerosAndBadSamples) {
  StreamingStats stats;
  EXPECT_EQ(stats.Quantile(0.5), 0.0);  // empty
  stats.Add(0.0);
  stats.Add(0.0);
  stats.Add(5e7);  // beyond kMaxValue: its bin is the last, max() exact
  stats.Add(std::nan(""));
  stats.Add(-1.0);
  EXPECT_EQ(stats.count(), 3);
  EXPECT_EQ(stats.rejected(), 2);
  EXPECT_EQ(stats.Quantile(0.5), 0.0);
  EXPECT_EQ(stats.max(), 5e7);
  EXPECT_LE(stats.Quantile(1.0), 5e7);
  // One sample: every quantile is it (clamped to [min, max]).
  StreamingStats one;
  one.Add(0.0123);
  EXPECT_EQ(one.Quantile(0.0), 0.0123);
  EXPECT_EQ(one.Quantile(0.95), 0.0123);
}

}  // namespace
}  // namespace saccade
