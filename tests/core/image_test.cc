// Image (saccade/core/image.h): the copy of pixels from another's memory, packed or strided.

#include "saccade/core/image.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "saccade/core/error.h"

namespace saccade {
namespace {

TEST(Image, CopiesPackedAndStridedRowsExactly) {
  constexpr int kWidth = 5, kHeight = 3;
  constexpr std::size_t kRow = kWidth * 3;
  for (const std::size_t stride : {kRow, kRow + 7}) {
    std::vector<uint8_t> source(stride * kHeight);
    std::iota(source.begin(), source.end(), uint8_t{1});
    const Image image(kWidth, kHeight, PixelFormat::kRgb8, source.data(), stride);
    ASSERT_EQ(image.size_bytes(), kRow * kHeight) << "stride " << stride;
    for (int y = 0; y < kHeight; ++y) {
      for (std::size_t x = 0; x < kRow; ++x) {
        ASSERT_EQ(image.row(y)[x], source[y * stride + x]) << "stride " << stride << " row " << y;
      }
    }
  }
  const Image empty(0, 4, PixelFormat::kGray8, nullptr, 0);
  EXPECT_TRUE(empty.empty());
}

TEST(Image, AShortStrideOrANegativeSizeIsRefusedNamingIt) {
  const std::vector<uint8_t> source(64);
  try {
    Image(8, 2, PixelFormat::kRgb8, source.data(), 23);
    FAIL() << "a stride shorter than a row was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("stride of 23 bytes"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("24 bytes"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Image(-1, 2, PixelFormat::kGray8, source.data(), 4), InvalidArgument);
}

}  // namespace
}  // namespace saccade
