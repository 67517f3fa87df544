#include "saccade/core/image_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>

#include "saccade/core/error.h"

namespace saccade {
namespace {

using ::testing::HasSubstr;

class ImageIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("saccade_image_io_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

Image Gradient(PixelFormat format, int width, int height) {
  Image image(width, height, format);
  for (std::size_t i = 0; i < image.size_bytes(); ++i)
    image.data()[i] = static_cast<uint8_t>(i * 7 + 3);
  return image;
}

TEST_F(ImageIoTest, RgbPngReadsBackInOpenCvAndInOurReader) {
  const Image image = Gradient(PixelFormat::kRgb8, 37, 11);
  WritePng(image.view(), dir_ / "rgb.png");
  const cv::Mat bgr = cv::imread((dir_ / "rgb.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(bgr.type(), CV_8UC3);
  ASSERT_EQ(bgr.cols, 37);
  for (int y = 0; y < 11; ++y)
    for (int x = 0; x < 37; ++x)
      for (int c = 0; c < 3; ++c)  // OpenCV stores B G R; row 0 is the top in both
        ASSERT_EQ(bgr.at<cv::Vec3b>(y, x)[2 - c], image.row(y)[3 * x + c]);
  const Image back = ReadImage(dir_ / "rgb.png");
  ASSERT_EQ(back.format(), PixelFormat::kRgb8);
  EXPECT_EQ(std::vector<uint8_t>(back.data(), back.data() + back.size_bytes()),
            std::vector<uint8_t>(image.data(), image.data() + image.size_bytes()));
}

TEST_F(ImageIoTest, SixteenBitPngKeepsEveryValue) {
  Image image(300, 2, PixelFormat::kGray16);
  auto* values = reinterpret_cast<uint16_t*>(image.data());
  for (int i = 0; i < 600; ++i) values[i] = static_cast<uint16_t>(i * 109);  // up to 65291
  WritePng(image.view(), dir_ / "depth.png");
  const cv::Mat read = cv::imread((dir_ / "depth.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(read.type(), CV_16UC1);
  for (int i = 0; i < 600; ++i) ASSERT_EQ(read.at<uint16_t>(i / 300, i % 300), values[i]);
  const Image back = ReadImage(dir_ / "depth.png");
  ASSERT_EQ(back.format(), PixelFormat::kGray16);
  EXPECT_EQ(reinterpret_cast<const uint16_t*>(back.data())[599], values[599]);
}

TEST_F(ImageIoTest, MissingAndCorruptFilesNameTheFile) {
  try {
    ReadImage(dir_ / "missing.png");
    FAIL() << "no error";
  } catch (const FileError& e) {
    EXPECT_THAT(e.what(), HasSubstr("missing.png"));
    EXPECT_THAT(e.what(), HasSubstr("cannot open"));
  }
  std::ofstream(dir_ / "corrupt.png") << "not a png at all";
  try {
    ReadImage(dir_ / "corrupt.png");
    FAIL() << "no error";
  } catch (const FileError& e) {
    EXPECT_THAT(e.what(), HasSubstr("corrupt.png"));
  }
}

TEST_F(ImageIoTest, AnImageLargerThanTheLimitIsRefusedFromItsHeader) {
  // A real PNG whose IHDR (CRC included) states 100000 x 100000 pixels: the size is refused
  // before anything is decoded or allocated (issue 18). Written as a large image would be,
  // then its IHDR patched: the CRC is recomputed so that the header is well-formed.
  WritePng(Gradient(PixelFormat::kRgb8, 4, 4).view(), dir_ / "huge.png");
  std::string bytes;
  {
    std::ifstream in(dir_ / "huge.png", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  ASSERT_EQ(bytes.substr(12, 4), "IHDR");
  const auto put32 = [&](std::size_t at, uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<char>((v >> (24 - 8 * i)) & 0xff);
  };
  put32(16, 100000);
  put32(20, 100000);
  const uLong crc = crc32(0, reinterpret_cast<const Bytef*>(bytes.data() + 12), 17);
  put32(29, static_cast<uint32_t>(crc));
  std::ofstream(dir_ / "huge.png", std::ios::binary) << bytes;
  try {
    ReadImage(dir_ / "huge.png");
    FAIL() << "no exception";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("huge.png: the image is 100000x100000 px, larger than "
                                         "saccade reads (16384 px a side"),
              std::string::npos)
        << e.what();
  }
}

TEST_F(ImageIoTest, FailedWriteLeavesNothingBehind) {
  const Image image = Gradient(PixelFormat::kRgb8, 4, 4);
  EXPECT_THROW(WritePng(image.view(), dir_ / "no_such_dir" / "x.png"), FileError);
  EXPECT_THROW(WritePng(Image(4, 4, PixelFormat::kFloat32).view(), dir_ / "f.png"),
               InvalidArgument);
  EXPECT_TRUE(std::filesystem::is_empty(dir_));
}

}  // namespace
}  // namespace saccade
