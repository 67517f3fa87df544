// The sensor noise's table of normal deviates (render/gl/internal_effects.h): the quantiles of
// the standard normal distribution, checked against the closed form of its CDF (erfc), and
// their packing into one 32-bit integer an entry as the final pass reads them. The noise in
// rendered images is proven by tests/render/effects_test.cc (NoiseTest: sigma within 2 %).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "render/gl/internal_effects.h"
#include "saccade/core/error.h"

namespace saccade::render::gl {
namespace {

constexpr int kEntries = kGaussianTableSide * kGaussianTableSide;

double Decode(uint32_t entry, int channel) {
  return static_cast<double>((entry >> (10 * channel)) & 1023u) * kGaussianStep - kGaussianRange;
}

TEST(GaussianTableTest, EachChannelHoldsTheNormalQuantilesAtUnitVariance) {
  const std::vector<float> table = GaussianTable();
  ASSERT_EQ(table.size(), 3u * kEntries);
  for (int c = 0; c < 3; ++c) {
    std::vector<double> z;
    for (int i = 0; i < kEntries; ++i) z.push_back(table[3 * i + c]);
    double sum = 0.0, sum2 = 0.0;
    for (double v : z) {
      sum += v;
      sum2 += v * v;
    }
    EXPECT_NEAR(sum / kEntries, 0.0, 1e-6) << c;
    EXPECT_NEAR(sum2 / kEntries, 1.0, 1e-5) << c;
    // Sorted, entry i is the quantile at (i + 1/2) / n: the normal CDF there, by erfc, within
    // the scale to unit variance (0.9997 of the tails' variance is kept) and float precision.
    std::sort(z.begin(), z.end());
    for (int i = 0; i < kEntries; i += 257) {
      const double p = 0.5 * std::erfc(-z[i] / std::sqrt(2.0));
      EXPECT_NEAR(p, (i + 0.5) / kEntries, 2e-4 * std::min(p, 1.0 - p) + 1e-7) << c << " " << i;
    }
  }
  // The channels are in orders of their own: entry by entry, nearly uncorrelated.
  double r01 = 0.0, r02 = 0.0, r12 = 0.0;
  for (int i = 0; i < kEntries; ++i) {
    r01 += table[3 * i] * table[3 * i + 1];
    r02 += table[3 * i] * table[3 * i + 2];
    r12 += table[3 * i + 1] * table[3 * i + 2];
  }
  EXPECT_LT(std::abs(r01 / kEntries), 0.02);
  EXPECT_LT(std::abs(r02 / kEntries), 0.02);
  EXPECT_LT(std::abs(r12 / kEntries), 0.02);
}

TEST(GaussianTableTest, PackedEntriesDecodeWithinHalfAStepKeepingMeanAndVariance) {
  const std::vector<float> table = GaussianTable();
  const std::vector<uint32_t> packed = PackGaussianTable(table);
  ASSERT_EQ(packed.size(), static_cast<std::size_t>(kEntries));
  double largest = 0.0;
  for (int c = 0; c < 3; ++c) {
    double sum = 0.0, sum2 = 0.0;
    for (int i = 0; i < kEntries; ++i) {
      const double z = Decode(packed[i], c);
      largest = std::max(largest, std::abs(z - table[3 * i + c]));
      sum += z;
      sum2 += z * z;
    }
    // The codes are symmetric about 0: the mean stays 0; rounding adds step^2 / 12 of variance.
    EXPECT_NEAR(sum / kEntries, 0.0, 1e-6) << c;
    EXPECT_NEAR(sum2 / kEntries, 1.0, 1e-4) << c;
  }
  EXPECT_LE(largest, 0.5 * kGaussianStep + 1e-6);
  EXPECT_LT(kGaussianStep, 0.01);  // a hundredth of sigma: far below one output DN

  // A deviate beyond the range is refused, not wrapped into another code.
  std::vector<float> wide = table;
  wide[4] = static_cast<float>(kGaussianRange + 0.1);
  EXPECT_THROW(PackGaussianTable(wide), Error);
}

// Every renderer of a process shares one packed table, made at the first call: it is the table
// packed above, entry for entry, and later calls return that same one.
TEST(GaussianTableTest, TheSharedPackedTableIsThePackedTableMadeOnce) {
  const std::vector<uint32_t>& shared = PackedGaussianTable();
  EXPECT_EQ(shared, PackGaussianTable(GaussianTable()));
  EXPECT_EQ(&PackedGaussianTable(), &shared);
}

}  // namespace
}  // namespace saccade::render::gl
