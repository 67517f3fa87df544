// The reader's side of the ROS 2 mapping (src/dds/internal_convert.h): sensor_msgs/Image read in
// place from its serialized bytes, checked against an independent serializer's bytes
// (Foxglove's, under Node) and against big-endian bytes written out by hand from the CDR rules;
// the map (mapping.map) as sensor_msgs/PointCloud2, field by field, both ways.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dds/internal_convert.h"
#include "reference_serializer.h"
#include "saccade/components/messages.h"
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
                        {1, 1, "rgba8", 4, 0, "", 1700000000, 999999999},
                        // Raw colour filter array mosaics (issue 45): one sample a pixel.
                        {6, 3, "bayer_rggb8", 1, 1, "left_optical", 2, 5},
                        {5, 2, "bayer_gbrg16", 2, 0, "right_optical", 3, 7}};
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
    EXPECT_EQ(internal::RosEncoding(image->format()), c.encoding);  // and back to its name
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

// The bytes of point `i`'s field at `offset` of a cloud's data.
float FloatAt(const sensor_msgs_msg_dds__PointCloud2_& cloud, uint32_t i, uint32_t offset) {
  float f = 0;
  std::memcpy(&f, cloud.data._buffer + i * cloud.point_step + offset, sizeof(f));
  return f;
}
uint32_t U32At(const sensor_msgs_msg_dds__PointCloud2_& cloud, uint32_t i, uint32_t offset) {
  uint32_t u = 0;
  std::memcpy(&u, cloud.data._buffer + i * cloud.point_step + offset, sizeof(u));
  return u;
}

void ExpectFields(const sensor_msgs_msg_dds__PointCloud2_& cloud,
                  const std::vector<std::string>& names) {
  ASSERT_EQ(cloud.fields._length, names.size());
  for (uint32_t i = 0; i < names.size(); ++i) {
    EXPECT_STREQ(cloud.fields._buffer[i].name, names[i].c_str());
    EXPECT_EQ(cloud.fields._buffer[i].offset, 4 * i) << names[i];
    EXPECT_EQ(cloud.fields._buffer[i].datatype, 7) << names[i] << ": FLOAT32 is 7";
    EXPECT_EQ(cloud.fields._buffer[i].count, 1u) << names[i];
  }
}

components::MapMessage SmallMap() {
  components::MapMessage map;
  map.time = 12.345678901;
  map.frame_index = 308;
  map.resolution_m = 0.02;
  map.occupied_W = {{1.25, -0.5, 0.75}, {1.5, 0.25, 1.75}, {-2.0, 3.0, 1.25}};
  map.inhibited = {{{1.0, 0.5, 1.2}, 0.15, 1.0}, {{-0.5, 2.0, 0.8}, 0.3, 0.25}};
  map.fused = 9;
  return map;
}

TEST(MapCloud, OccupiedVoxelsAreFloat32XyzWithRgbByHeight) {
  const components::MapMessage map = SmallMap();
  internal::Holder holder;
  sensor_msgs_msg_dds__PointCloud2_ cloud{};
  internal::FillMapCloud(map, holder, &cloud);
  EXPECT_EQ(cloud.header.stamp.sec, 12);
  EXPECT_EQ(cloud.header.stamp.nanosec, 345678901u);
  EXPECT_STREQ(cloud.header.frame_id, "world");
  EXPECT_EQ(cloud.height, 1u);
  EXPECT_EQ(cloud.width, 3u);
  ExpectFields(cloud, {"x", "y", "z", "rgb"});
  EXPECT_FALSE(cloud.is_bigendian);
  EXPECT_EQ(cloud.point_step, 16u);
  EXPECT_EQ(cloud.row_step, 48u);
  EXPECT_TRUE(cloud.is_dense);
  ASSERT_EQ(cloud.data._length, 48u);
  for (uint32_t i = 0; i < 3; ++i) {
    EXPECT_EQ(FloatAt(cloud, i, 0), static_cast<float>(map.occupied_W[i].x())) << i;
    EXPECT_EQ(FloatAt(cloud, i, 4), static_cast<float>(map.occupied_W[i].y())) << i;
    EXPECT_EQ(FloatAt(cloud, i, 8), static_cast<float>(map.occupied_W[i].z())) << i;
  }
  // z from 0.75 (blue) to 1.75 (red); 1.25 is half way: green. PCL's packing 0x00RRGGBB.
  EXPECT_EQ(U32At(cloud, 0, 12), 0x0000ffu);
  EXPECT_EQ(U32At(cloud, 1, 12), 0xff0000u);
  EXPECT_EQ(U32At(cloud, 2, 12), 0x00ff00u);
  EXPECT_EQ(internal::HeightColor(0.25), 0x00ffffu);
  EXPECT_EQ(internal::HeightColor(0.75), 0xffff00u);
  EXPECT_EQ(internal::HeightColor(-3.0), 0x0000ffu);

  // An empty map is a cloud of no points with the same fields.
  internal::FillMapCloud(components::MapMessage{}, holder, &cloud);
  EXPECT_EQ(cloud.width, 0u);
  EXPECT_EQ(cloud.data._length, 0u);
  ExpectFields(cloud, {"x", "y", "z", "rgb"});
}

TEST(MapCloud, InhibitedPlacesCarryStrengthAndRadius) {
  const components::MapMessage map = SmallMap();
  internal::Holder holder;
  sensor_msgs_msg_dds__PointCloud2_ cloud{};
  internal::FillInhibitedCloud(map, holder, &cloud);
  EXPECT_STREQ(cloud.header.frame_id, "world");
  EXPECT_EQ(cloud.header.stamp.sec, 12);
  EXPECT_EQ(cloud.width, 2u);
  EXPECT_EQ(cloud.height, 1u);
  ExpectFields(cloud, {"x", "y", "z", "strength", "radius"});
  EXPECT_EQ(cloud.point_step, 20u);
  EXPECT_EQ(cloud.row_step, 40u);
  EXPECT_TRUE(cloud.is_dense);
  for (uint32_t i = 0; i < 2; ++i) {
    const components::InhibitedPlace& p = map.inhibited[i];
    EXPECT_EQ(FloatAt(cloud, i, 0), static_cast<float>(p.p_W.x()));
    EXPECT_EQ(FloatAt(cloud, i, 8), static_cast<float>(p.p_W.z()));
    EXPECT_EQ(FloatAt(cloud, i, 12), static_cast<float>(p.strength));
    EXPECT_EQ(FloatAt(cloud, i, 16), static_cast<float>(p.radius_m));
  }
  // And back, as the reader takes them.
  std::vector<components::InhibitedPlace> places;
  std::string error;
  ASSERT_TRUE(internal::InhibitedOf(cloud, &places, &error)) << error;
  ASSERT_EQ(places.size(), 2u);
  EXPECT_EQ(places[1].p_W.y(), 2.0);
  EXPECT_EQ(places[1].radius_m, static_cast<double>(0.3f));
  EXPECT_EQ(places[1].strength, 0.25);
}

// Another publisher's cloud (a ROS 2 node's), serialized by Foxglove's writer: FLOAT64 and
// FLOAT32 fields at offsets of its own, a field saccade does not know, two rows with padding
// at the end of each. The reader finds x, y, z by name.
TEST(MapCloud, ReadsAnotherPublishersCloudByFieldName) {
  const double xyz[2][2][3] = {{{0.5, 1.5, 2.5}, {-1.0, 0.25, 3.0}},
                               {{4.0, -4.5, 0.125}, {7.5, 8.0, -9.0}}};
  constexpr uint32_t kPointStep = 32, kRowStep = 2 * kPointStep + 8;
  std::vector<uint8_t> data(2 * kRowStep, 0xEE);
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 2; ++c) {
      uint8_t* p = data.data() + r * kRowStep + c * kPointStep;
      const float intensity = 100.0f, z = static_cast<float>(xyz[r][c][2]);
      std::memcpy(p, &intensity, 4);
      std::memcpy(p + 8, &xyz[r][c][0], 8);
      std::memcpy(p + 16, &xyz[r][c][1], 8);
      std::memcpy(p + 24, &z, 4);
    }
  }
  const auto Field = [](const char* name, int offset, int datatype) {
    return json{{"name", name}, {"offset", offset}, {"datatype", datatype}, {"count", 1}};
  };
  const json message = {
      {"header", {{"stamp", {{"sec", 3}, {"nanosec", 500000000}}}, {"frame_id", "world"}}},
      {"height", 2},
      {"width", 2},
      {"fields",
       {Field("intensity", 0, 7), Field("x", 8, 8), Field("y", 16, 8), Field("z", 24, 7)}},
      {"is_bigendian", false},
      {"point_step", kPointStep},
      {"row_step", kRowStep},
      {"data", {{"base64", Base64(data)}}},
      {"is_dense", true}};
  const std::vector<std::string> reference = ReferenceSerialize(
      json::array({{{"type", "sensor_msgs/PointCloud2"}, {"message", message}}}));
  ASSERT_EQ(reference.size(), 1u);
  const std::vector<uint8_t> bytes = Unhex(reference[0]);
  sensor_msgs_msg_dds__PointCloud2_ cloud{};
  std::string error;
  ASSERT_TRUE(internal::DeserializeCdr(sensor_msgs_msg_dds__PointCloud2__desc, bytes.data(),
                                       bytes.size(), &cloud, &error))
      << error;
  components::MapMessage map;
  const bool read = internal::MapOf(cloud, &map, &error);
  dds_stream_free_sample(&cloud, sensor_msgs_msg_dds__PointCloud2__desc.m_ops);
  ASSERT_TRUE(read) << error;
  EXPECT_EQ(map.time, 3.5);
  ASSERT_EQ(map.occupied_W.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    const double* want = xyz[i / 2][i % 2];
    EXPECT_EQ(map.occupied_W[i], Eigen::Vector3d(want[0], want[1], want[2])) << i;
  }
}

TEST(MapCloud, RefusesCloudsItCannotReadSayingWhy) {
  const components::MapMessage map = SmallMap();
  const auto ErrorOf = [&](const std::function<void(sensor_msgs_msg_dds__PointCloud2_&)>& spoil) {
    internal::Holder holder;
    sensor_msgs_msg_dds__PointCloud2_ cloud{};
    internal::FillMapCloud(map, holder, &cloud);
    spoil(cloud);
    components::MapMessage out;
    std::string error;
    return internal::MapOf(cloud, &out, &error) ? std::string("(read)") : error;
  };
  EXPECT_EQ(ErrorOf([](auto&) {}), "(read)");
  EXPECT_EQ(ErrorOf([](auto& c) { c.fields._buffer[2].name = const_cast<char*>("height"); }),
            "the cloud has no field 'z' (its fields: x, y, height, rgb)");
  EXPECT_EQ(ErrorOf([](auto& c) { c.fields._buffer[1].datatype = 2; }),
            "field 'y' is datatype 2 count 1 at offset 4 of a 16-byte point; expected one "
            "FLOAT32 (7) or FLOAT64 (8) inside the point");
  EXPECT_NE(ErrorOf([](auto& c) { c.fields._buffer[0].count = 3; }).find("count 3"),
            std::string::npos);
  EXPECT_NE(ErrorOf([](auto& c) { c.fields._buffer[2].offset = 14; }).find("offset 14"),
            std::string::npos);
  EXPECT_EQ(ErrorOf([](auto& c) { c.is_bigendian = true; }),
            "big-endian point clouds are not supported");
  EXPECT_EQ(ErrorOf([](auto& c) { c.data._length -= 1; }),
            "3x1 points of 16 bytes: row_step 48 and 47 bytes of data are too short");
  EXPECT_EQ(ErrorOf([](auto& c) { c.header.frame_id = const_cast<char*>("map"); }),
            "point cloud in frame 'map', expected 'world'");
}

}  // namespace
}  // namespace saccade::dds
