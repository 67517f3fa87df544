// The reader's side of the ROS 2 mapping (src/dds/internal_convert.h): sensor_msgs/Image read in
// place from its serialized bytes, checked against an independent serializer's bytes
// (Foxglove's, under Node) and against big-endian bytes written out by hand from the CDR rules.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "dds/internal_convert.h"
#include "reference_serializer.h"
#include "saccade/core/image.h"

namespace saccade::dds {
namespace {

using namespace saccade::dds::testing;
using nlohmann::json;

std::vector<uint8_t> Unhex(const std::string& hex) {
  std::vector<uint8_t> bytes;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2) {
    bytes.push_back(static_cast<uint8_t>(std::stoi(hex.substr(i, 2), nullptr, 16)));
  }
  return bytes;
}

std::string Base64(const std::vector<uint8_t>& d) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < d.size(); i += 3) {
    const uint32_t v = (uint32_t{d[i]} << 16) | (i + 1 < d.size() ? uint32_t{d[i + 1]} << 8 : 0) |
                       (i + 2 < d.size() ? uint32_t{d[i + 2]} : 0);
    out += k[(v >> 18) & 63];
    out += k[(v >> 12) & 63];
    out += i + 1 < d.size() ? k[(v >> 6) & 63] : '=';
    out += i + 2 < d.size() ? k[v & 63] : '=';
  }
  return out;
}

struct Case {
  int width, height;
  const char* encoding;
  int bytes_per_pixel;
  uint32_t padding;  // step beyond a packed row
  const char* frame;
  int32_t sec;
  uint32_t nanosec;
};

TEST(ImageViewOfCdr, ReadsAnIndependentSerializersImagesExactly) {
  // Odd sizes and frame names, so that strings and the pixels leave fields unaligned; one
  // image with rows padded (step wider than a row).
  const Case cases[] = {{5, 3, "rgb8", 3, 0, "left_optical", 12, 345678901},
                        {7, 2, "mono8", 1, 3, "r", 0, 120000000},
                        {1, 1, "rgba8", 4, 0, "", 1700000000, 999999999}};
  json inputs = json::array();
  std::vector<std::vector<uint8_t>> pixels;
  for (const Case& c : cases) {
    const uint32_t step = c.width * c.bytes_per_pixel + c.padding;
    std::vector<uint8_t> data(step * c.height);
    for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<uint8_t>(37 * i + 11);
    pixels.push_back(data);
    inputs.push_back(
        {{"type", "sensor_msgs/Image"},
         {"message",
          {{"header", {{"stamp", {{"sec", c.sec}, {"nanosec", c.nanosec}}}, {"frame_id", c.frame}}},
           {"height", c.height},
           {"width", c.width},
           {"encoding", c.encoding},
           {"is_bigendian", 0},
           {"step", step},
           {"data", {{"base64", Base64(data)}}}}}});
  }
  const std::vector<std::string> reference = ReferenceSerialize(inputs);
  ASSERT_EQ(reference.size(), std::size(cases));
  for (std::size_t k = 0; k < std::size(cases); ++k) {
    const Case& c = cases[k];
    const std::vector<uint8_t> bytes = Unhex(reference[k]);
    sensor_msgs_msg_dds__Image_ msg{};
    std::string error;
    ASSERT_TRUE(internal::ImageViewOfCdr(bytes.data(), bytes.size(), &msg, &error)) << error;
    EXPECT_EQ(msg.header.stamp.sec, c.sec);
    EXPECT_EQ(msg.header.stamp.nanosec, c.nanosec);
    EXPECT_STREQ(msg.header.frame_id, c.frame);
    EXPECT_EQ(msg.width, static_cast<uint32_t>(c.width));
    EXPECT_EQ(msg.height, static_cast<uint32_t>(c.height));
    EXPECT_STREQ(msg.encoding, c.encoding);
    EXPECT_EQ(msg.step, c.width * c.bytes_per_pixel + c.padding);
    ASSERT_EQ(msg.data._length, pixels[k].size());
    EXPECT_EQ(std::memcmp(msg.data._buffer, pixels[k].data(), pixels[k].size()), 0);
    // The image made of it: rows packed, the padding left out.
    internal::ImagePool pool;
    const std::shared_ptr<Image> image = internal::ImageOf(msg, &error, &pool);
    ASSERT_NE(image, nullptr) << error;
    for (int y = 0; y < c.height; ++y) {
      EXPECT_EQ(std::memcmp(image->row(y), &pixels[k][y * msg.step], image->stride()), 0) << y;
    }
    // Every prefix that ends before the pixels do is refused, naming what it ends in.
    const std::size_t end =
        static_cast<std::size_t>(msg.data._buffer - bytes.data()) + msg.data._length;
    for (std::size_t n = 0; n < end; ++n) {
      sensor_msgs_msg_dds__Image_ cut{};
      ASSERT_FALSE(internal::ImageViewOfCdr(bytes.data(), n, &cut, &error)) << n;
      EXPECT_TRUE(error.find("ends inside its") != std::string::npos ||
                  error.find("encapsulation header") != std::string::npos)
          << error;
    }
  }
}

TEST(ImageViewOfCdr, ReadsBigEndianCdrAndRefusesOtherEncapsulations) {
  // A 2 x 1 mono8 image, frame "cam", stamp 1 s 2 ns, written out by hand in big-endian CDR
  // (XCDR1): alignment counts from after the 4-byte encapsulation header.
  const std::vector<uint8_t> big = {
      0x00, 0x00, 0x00, 0x00,                                     // CDR_BE, options
      0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x02,             // stamp
      0x00, 0x00, 0x00, 0x04, 'c',  'a',  'm',  0x00,             // frame_id
      0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x02,             // height, width
      0x00, 0x00, 0x00, 0x06, 'm',  'o',  'n',  'o',  '8', 0x00,  // encoding
      0x00, 0x00,                                                 // is_bigendian, padding to 4
      0x00, 0x00, 0x00, 0x02,                                     // step
      0x00, 0x00, 0x00, 0x02, 0xAB, 0xCD};                        // data
  sensor_msgs_msg_dds__Image_ msg{};
  std::string error;
  ASSERT_TRUE(internal::ImageViewOfCdr(big.data(), big.size(), &msg, &error)) << error;
  EXPECT_EQ(msg.header.stamp.sec, 1);
  EXPECT_EQ(msg.header.stamp.nanosec, 2u);
  EXPECT_STREQ(msg.header.frame_id, "cam");
  EXPECT_EQ(msg.height, 1u);
  EXPECT_EQ(msg.width, 2u);
  EXPECT_STREQ(msg.encoding, "mono8");
  EXPECT_EQ(msg.step, 2u);
  ASSERT_EQ(msg.data._length, 2u);
  EXPECT_EQ(msg.data._buffer[0], 0xAB);
  EXPECT_EQ(msg.data._buffer[1], 0xCD);

  std::vector<uint8_t> other = big;
  other[1] = 0x06;  // XCDR2, little-endian: not what ROS 2 writes
  EXPECT_FALSE(internal::ImageViewOfCdr(other.data(), other.size(), &msg, &error));
  EXPECT_NE(error.find("encapsulation 0x0006"), std::string::npos) << error;
  // A string without its terminating NUL, and a length past the end, are refused.
  std::vector<uint8_t> unterminated = big;
  unterminated[19] = 'x';
  EXPECT_FALSE(internal::ImageViewOfCdr(unterminated.data(), unterminated.size(), &msg, &error));
  EXPECT_NE(error.find("header.frame_id"), std::string::npos) << error;
  // A width past what an image can hold, with no rows to hold it (so no data is missing), is
  // refused by the conversion, not thrown.
  std::vector<uint8_t> wide = big;
  wide[20 + 3] = 0x00;  // height 0
  wide[24] = 0x80;      // width 0x80000002
  ASSERT_TRUE(internal::ImageViewOfCdr(wide.data(), wide.size(), &msg, &error)) << error;
  EXPECT_EQ(internal::ImageOf(msg, &error), nullptr);
  EXPECT_NE(error.find("too large"), std::string::npos) << error;
  std::vector<uint8_t> overlong = big;
  overlong[47] = 0x03;  // three bytes of data claimed, two there
  EXPECT_FALSE(internal::ImageViewOfCdr(overlong.data(), overlong.size(), &msg, &error));
  EXPECT_NE(error.find("data"), std::string::npos) << error;
}

}  // namespace
}  // namespace saccade::dds
