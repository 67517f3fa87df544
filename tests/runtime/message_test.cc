// Message names, JSON round trips, the message registry, and image metadata without pixels.

#include "saccade/runtime/message.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

namespace saccade::runtime {
namespace {

// A message type as another module would declare it.
struct Target {
  double x = 0.0;
  bool operator==(const Target&) const = default;
};

}  // namespace

template <>
struct MessageTraits<Target> {
  static constexpr const char* kName = "test.target";
  static nlohmann::json ToJson(const Target& m) { return {{"x", m.x}}; }
  static Target FromJson(const nlohmann::json& j) { return {DecodeField<double>(j, kName, "x")}; }
};

namespace {

template <Message T>
T RoundTrip(const T& message) {
  // Through text, as on the browser link.
  const std::string text = MessageTraits<T>::ToJson(message).dump();
  return MessageTraits<T>::FromJson(nlohmann::json::parse(text));
}

TEST(MessageTest, TickRoundTripsThroughText) {
  const Tick tick{123456789012, 0.1 + 0.2};  // a time with no short decimal form
  EXPECT_EQ(RoundTrip(tick), tick);
  EXPECT_EQ(MessageName<Tick>(), std::string("runtime.tick"));
}

TEST(MessageTest, ValueAndTextRoundTrip) {
  EXPECT_EQ(RoundTrip(Value{-1.0 / 3.0}), Value{-1.0 / 3.0});
  EXPECT_EQ(RoundTrip(Text{"fixate \"face\" ü"}), Text{"fixate \"face\" ü"});
}

TEST(MessageTest, EnvelopeNamesTheType) {
  const nlohmann::json envelope = ToEnvelope(Value{2.5});
  EXPECT_EQ(envelope["type"], "runtime.value");
  EXPECT_EQ(envelope["data"]["value"], 2.5);
}

TEST(MessageTest, ImageJsonCarriesMetadataNotPixels) {
  auto image = std::make_shared<Image>(64, 48, PixelFormat::kRgb8);
  image->metadata().camera = "left";
  image->metadata().frame_index = 17;
  image->metadata().time = 0.68;
  image->metadata().exposure_s = 0.008;
  image->metadata().gain_db = 6.5;
  image->metadata().focus_m = 1.25;
  image->data()[0] = 200;
  const nlohmann::json json = MessageTraits<ImageMessage>::ToJson({image});
  EXPECT_EQ(json, (nlohmann::json{{"camera", "left"},
                                  {"frame_index", 17},
                                  {"time", 0.68},
                                  {"width", 64},
                                  {"height", 48},
                                  {"format", "rgb8"},
                                  {"exposure_s", 0.008},
                                  {"gain_db", 6.5},
                                  {"focus_m", 1.25}}));
  EXPECT_LT(json.dump().size(), 200u);  // no pixel data

  const ImageMessage back = MessageTraits<ImageMessage>::FromJson(json);
  ASSERT_TRUE(back.image);
  EXPECT_EQ(back.image->width(), 64);
  EXPECT_EQ(back.image->height(), 48);
  EXPECT_EQ(back.image->format(), PixelFormat::kRgb8);
  EXPECT_EQ(back.image->metadata().camera, "left");
  EXPECT_EQ(back.image->metadata().frame_index, 17);
  EXPECT_EQ(back.image->metadata().time, 0.68);
  EXPECT_EQ(back.image->metadata().exposure_s, 0.008);
  EXPECT_EQ(back.image->metadata().gain_db, 6.5);
  EXPECT_EQ(back.image->metadata().focus_m, 1.25);
  EXPECT_EQ(back.image->data()[0], 0);  // pixels do not travel
  EXPECT_EQ(MessageTraits<ImageMessage>::ToJson(back), json);
}

TEST(MessageTest, ImageJsonWithoutCameraControlsDecodesToNone) {
  // Older senders' JSON has no camera controls: absent or null is ImageMetadata's 0 ("none");
  // a control of another type is refused naming it.
  nlohmann::json json = {{"camera", "left"}, {"frame_index", 1},  {"time", 0.04},      {"width", 4},
                         {"height", 2},      {"format", "gray8"}, {"focus_m", nullptr}};
  const ImageMessage back = MessageTraits<ImageMessage>::FromJson(json);
  ASSERT_TRUE(back.image);
  EXPECT_EQ(back.image->metadata().exposure_s, 0.0);
  EXPECT_EQ(back.image->metadata().focus_m, 0.0);
  json["gain_db"] = "loud";
  try {
    MessageTraits<ImageMessage>::FromJson(json);
    ADD_FAILURE() << "a gain of text was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("gain_db"), std::string::npos) << e.what();
  }
}

TEST(MessageTest, BayerImageJsonNamesItsRosEncoding) {
  // A raw colour filter array mosaic (issue 45): its format is ROS's encoding, both ways.
  for (PixelFormat format : {PixelFormat::kBayerRggb8, PixelFormat::kBayerGbrg16}) {
    auto image = std::make_shared<Image>(6, 4, format);
    const nlohmann::json json = MessageTraits<ImageMessage>::ToJson({image});
    EXPECT_EQ(json["format"], format == PixelFormat::kBayerRggb8 ? "bayer_rggb8" : "bayer_gbrg16");
    const ImageMessage back = MessageTraits<ImageMessage>::FromJson(json);
    ASSERT_TRUE(back.image);
    EXPECT_EQ(back.image->format(), format);
    EXPECT_EQ(back.image->size_bytes(), 6u * 4u * (format == PixelFormat::kBayerRggb8 ? 1 : 2));
  }
}

TEST(MessageTest, NullImageIsJsonNull) {
  EXPECT_TRUE(MessageTraits<ImageMessage>::ToJson({}).is_null());
  EXPECT_FALSE(MessageTraits<ImageMessage>::FromJson(nullptr).image);
}

TEST(MessageTest, BadJsonNamesTypeAndField) {
  try {
    MessageTraits<Tick>::FromJson({{"step", 1}});
    FAIL() << "no exception";
  } catch (const Error& error) {
    EXPECT_STREQ(error.what(), "runtime.tick: missing field 'time'");
  }
  try {
    MessageTraits<Tick>::FromJson({{"step", "one"}, {"time", 0.0}});
    FAIL() << "no exception";
  } catch (const Error& error) {
    EXPECT_STREQ(error.what(), "runtime.tick: field 'step': expected an integer, got \"one\"");
  }
  nlohmann::json huge =
      MessageTraits<ImageMessage>::ToJson({std::make_shared<Image>(2, 2, PixelFormat::kGray8)});
  huge["width"] = 1000000;
  try {
    MessageTraits<ImageMessage>::FromJson(huge);
    FAIL() << "no exception";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("field 'width'"), std::string::npos);
  }
  huge["width"] = 2;
  huge["format"] = "bgr8";
  EXPECT_THROW(MessageTraits<ImageMessage>::FromJson(huge), Error);
}

TEST(MessageRegistryTest, GlobalHoldsRuntimeTypesAndAcceptsOthers) {
  MessageRegistry& registry = MessageRegistry::Global();
  for (const char* name : {"runtime.tick", "runtime.value", "runtime.text", "runtime.image"}) {
    EXPECT_NE(registry.Find(name), nullptr) << name;
  }
  EXPECT_EQ(registry.Find("test.target"), nullptr);
  registry.Register<Target>();
  registry.Register<Target>();  // idempotent
  const MessageType* type = registry.Find("test.target");
  ASSERT_NE(type, nullptr);
  const Target target{4.5};
  const nlohmann::json json = type->to_json(&target);
  EXPECT_EQ(json["x"], 4.5);
  const std::shared_ptr<const void> back = type->from_json(json);
  EXPECT_EQ(*static_cast<const Target*>(back.get()), target);
}

}  // namespace
}  // namespace saccade::runtime
