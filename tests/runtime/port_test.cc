// Ports: typed inputs and outputs, connection checks, delayed delivery, JSON taps.

#include "saccade/runtime/port.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace saccade::runtime {
namespace {

TEST(PortTest, ImmediateInputKeepsLatestAndFreshness) {
  Output<Value> out("out");
  Input<Value> in("in", /*required=*/false);
  EXPECT_EQ(out.message_type(), "runtime.value");
  EXPECT_FALSE(in.has_value());
  EXPECT_EQ(in.get(), nullptr);
  EXPECT_THROW(in.value(), Error);
  in.ConnectFrom(out, 0, nullptr);
  EXPECT_TRUE(in.connected());
  out.Emit(Value{1.0});
  out.Emit(Value{2.0});
  EXPECT_TRUE(in.fresh());
  EXPECT_EQ(in.value().value, 2.0);
  in.MarkSeen();
  EXPECT_FALSE(in.fresh());
  EXPECT_EQ(in.value().value, 2.0);  // kept
}

TEST(PortTest, DelayedInputHoldsMessageUntilNextStep) {
  Output<Value> out("out");
  Input<Value> in("in", false);
  double delivery_seconds = -1.0;
  in.ConnectFrom(out, 1, [&](double s) { delivery_seconds = s; });
  out.Emit(Value{5.0});
  EXPECT_GE(delivery_seconds, 0.0);
  EXPECT_FALSE(in.has_value());
  in.DeliverDelayed();
  EXPECT_TRUE(in.fresh());
  EXPECT_EQ(in.value().value, 5.0);
}

TEST(PortTest, ConnectingOtherTypeOrTwiceIsRejected) {
  Output<Text> text("label");
  Output<Value> value("out");
  Input<Value> in("in", false);
  try {
    in.ConnectFrom(text, 0, nullptr);
    FAIL() << "no exception";
  } catch (const InvalidArgument& error) {
    EXPECT_STREQ(error.what(),
                 "output 'label' sends runtime.text, input 'in' expects runtime.value");
  }
  in.ConnectFrom(value, 0, nullptr);
  EXPECT_THROW(in.ConnectFrom(value, 0, nullptr), InvalidArgument);
}

TEST(PortTest, OutputCanBeTappedAsJson) {
  Output<Tick> out("tick");
  std::vector<nlohmann::json> seen;
  out.ConnectJson([&](const nlohmann::json& j) { seen.push_back(j); });
  EXPECT_EQ(out.subscriber_count(), 1u);
  out.Emit(Tick{3, 0.12});
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0], (nlohmann::json{{"step", 3}, {"time", 0.12}}));
}

}  // namespace
}  // namespace saccade::runtime
