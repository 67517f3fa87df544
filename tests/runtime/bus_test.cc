// Signals (one-to-many, in order, images shared) and methods (one-to-one, errors named).

#include "saccade/runtime/bus.h"

#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/runtime/message.h"

namespace saccade::runtime {
namespace {

TEST(SignalTest, DeliversToEverySubscriberInConnectionOrder) {
  Signal<int> signal("numbers");
  std::vector<std::string> calls;
  signal.Connect([&](const int& v) { calls.push_back("a" + std::to_string(v)); });
  signal.Connect([&](const int& v) { calls.push_back("b" + std::to_string(v)); });
  signal.Connect([&](const int& v) { calls.push_back("c" + std::to_string(v)); });
  signal.Emit(1);
  signal.Emit(2);
  EXPECT_EQ(calls, (std::vector<std::string>{"a1", "b1", "c1", "a2", "b2", "c2"}));
  EXPECT_EQ(signal.subscriber_count(), 3u);
}

TEST(SignalTest, EmitWithoutSubscribersDoesNothing) {
  Signal<int> signal;
  EXPECT_NO_THROW(signal.Emit(3));
}

TEST(SignalTest, DisconnectRemovesOnlyThatSubscriber) {
  Signal<int> signal;
  int a = 0;
  int b = 0;
  const ConnectionId id_a = signal.Connect([&](const int&) { ++a; });
  signal.Connect([&](const int&) { ++b; });
  EXPECT_NE(id_a, 0u);
  EXPECT_TRUE(signal.Disconnect(id_a));
  EXPECT_FALSE(signal.Disconnect(id_a));
  signal.Emit(0);
  EXPECT_EQ(a, 0);
  EXPECT_EQ(b, 1);
}

TEST(SignalTest, EmptySlotIsRejected) {
  Signal<int> signal("s");
  EXPECT_THROW(signal.Connect(nullptr), InvalidArgument);
}

TEST(SignalTest, MessagePassedByReferenceNotCopied) {
  // A message type that counts its copies.
  struct Counted {
    int* copies;
    explicit Counted(int* c) : copies(c) {}
    Counted(const Counted& other) : copies(other.copies) { ++*copies; }
  };
  int copies = 0;
  Signal<Counted> signal;
  const Counted* seen[2] = {nullptr, nullptr};
  signal.Connect([&](const Counted& m) { seen[0] = &m; });
  signal.Connect([&](const Counted& m) { seen[1] = &m; });
  const Counted message(&copies);
  signal.Emit(message);
  EXPECT_EQ(copies, 0);
  EXPECT_EQ(seen[0], &message);
  EXPECT_EQ(seen[1], &message);
}

TEST(SignalTest, ImagesAreSharedNeverCopied) {
  auto pixels = std::make_shared<Image>(640, 480, PixelFormat::kRgb8);
  pixels->data()[0] = 42;
  const uint8_t* const data = pixels->data();
  const ImageMessage message{std::move(pixels)};
  ASSERT_EQ(message.image.use_count(), 1);

  Signal<ImageMessage> signal("camera.left");
  std::vector<std::shared_ptr<const Image>> kept;  // subscribers that keep the frame
  std::vector<long> use_counts;
  for (int i = 0; i < 3; ++i) {
    signal.Connect([&](const ImageMessage& m) {
      use_counts.push_back(m.image.use_count());
      kept.push_back(m.image);
    });
  }
  signal.Emit(message);
  ASSERT_EQ(kept.size(), 3u);
  for (const auto& image : kept) {
    EXPECT_EQ(image.get(), message.image.get());  // the same Image object
    EXPECT_EQ(image->data(), data);               // the same pixel buffer
  }
  // Each subscriber saw only the sender's reference plus those kept before it: no copy of the
  // message (which would add a reference) was made on the way.
  EXPECT_EQ(use_counts, (std::vector<long>{1, 2, 3}));
  EXPECT_EQ(message.image.use_count(), 4);
}

TEST(MethodTest, CallReturnsTheHandlersReply) {
  Method<int, std::string> method("head.describe");
  method.Bind([](const int& v) { return "got " + std::to_string(v); });
  EXPECT_TRUE(method.bound());
  EXPECT_EQ(method.Call(7), "got 7");
}

TEST(MethodTest, CallWithoutHandlerThrowsNamingTheMethod) {
  Method<int, int> method("head.move_to");
  try {
    method.Call(1);
    FAIL() << "no exception";
  } catch (const MethodError& error) {
    EXPECT_EQ(error.method(), "head.move_to");
    EXPECT_NE(std::string(error.what()).find("method 'head.move_to'"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("no handler"), std::string::npos);
  }
}

TEST(MethodTest, SecondHandlerIsRejected) {
  Method<int, int> method("head.move_to");
  method.Bind([](const int& v) { return v; });
  try {
    method.Bind([](const int& v) { return -v; });
    FAIL() << "no exception";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("head.move_to"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("already bound"), std::string::npos);
  }
  EXPECT_EQ(method.Call(5), 5);  // the first handler stays
  method.Unbind();
  EXPECT_FALSE(method.bound());
  method.Bind([](const int& v) { return -v; });
  EXPECT_EQ(method.Call(5), -5);
}

TEST(MethodTest, ThrowingHandlerIsWrappedWithItsMessage) {
  Method<int, int> method("head.move_to");
  method.Bind([](const int&) -> int { throw std::runtime_error("joint limit exceeded"); });
  try {
    method.Call(1);
    FAIL() << "no exception";
  } catch (const MethodError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("method 'head.move_to'"), std::string::npos) << what;
    EXPECT_NE(what.find("joint limit exceeded"), std::string::npos) << what;
  }
}

TEST(MethodTest, MethodErrorIsASaccadeError) {
  Method<int, int> method("m");
  EXPECT_THROW(method.Call(0), Error);
}

}  // namespace
}  // namespace saccade::runtime
