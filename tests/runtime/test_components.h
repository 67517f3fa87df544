#pragma once
// Small components for the runtime tests, registered in a registry of their own.

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/runtime/component.h"
#include "saccade/runtime/component_registry.h"
#include "saccade/runtime/message.h"

namespace saccade::runtime::testing {

/// Emits Value{start + step} on "out" every `every` steps (default 1).
class Source : public Component {
 public:
  Source() : out_(AddOutput<Value>("out")) {}
  void Configure(const nlohmann::json& params) override {
    if (params.contains("start")) {
      if (!params["start"].is_number()) throw InvalidArgument("'start' must be a number");
      start_ = params["start"].get<double>();
    }
    every_ = params.value("every", int64_t{1});
  }
  void Step(const StepContext& context) override {
    if (context.step % every_ != 0) return;
    out_.Emit(Value{start_ + static_cast<double>(context.step)});
  }

 private:
  Output<Value>& out_;
  double start_ = 0.0;
  int64_t every_ = 1;
};

/// Emits a uniform draw in [0, 1) per step from an engine seeded with the component's seed.
class RandomSource : public Component {
 public:
  RandomSource() : out_(AddOutput<Value>("out")) {}
  void Start() override { engine_.seed(seed()); }
  void Step(const StepContext& context) override {
    EXPECT_EQ(context.seed, seed());
    // 53 random bits: exact and portable, unlike std::uniform_real_distribution.
    out_.Emit(Value{static_cast<double>(engine_() >> 11) * 0x1.0p-53});
  }

 private:
  Output<Value>& out_;
  std::mt19937_64 engine_;
};

/// Forwards the latest Value on "in" plus one to "out" (nothing before the first message).
class Relay : public Component {
 public:
  Relay() : in_(AddInput<Value>("in")), out_(AddOutput<Value>("out")) {}
  void Step(const StepContext&) override {
    if (in_.has_value()) out_.Emit(Value{in_.value().value + 1.0});
  }

 private:
  Input<Value>& in_;
  Output<Value>& out_;
};

/// What a Recorder saw at one step.
struct Record {
  int64_t step = 0;
  double time = 0.0;
  bool has_value = false;
  bool fresh = false;
  double value = 0.0;
  bool while_waiting = false;  ///< the context offered StepContext::while_waiting
};

/// Records its Value input each step; calls StepContext::while_waiting once when offered.
class Recorder : public Component {
 public:
  Recorder() : in_(AddInput<Value>("in")) {}
  void Step(const StepContext& context) override {
    records.push_back({context.step, context.time, in_.has_value(), in_.fresh(),
                       in_.has_value() ? in_.value().value : 0.0,
                       context.while_waiting != nullptr});
    if (context.while_waiting != nullptr) (*context.while_waiting)();
  }
  std::vector<Record> records;

 private:
  Input<Value>& in_;
};

/// A sink whose input "in" must be connected.
class RequiredSink : public Component {
 public:
  RequiredSink() { AddInput<Value>("in", /*required=*/true); }
  void Step(const StepContext&) override {}
};

/// Takes an image (type runtime.image) on "image".
class ImageSink : public Component {
 public:
  ImageSink() { AddInput<ImageMessage>("image"); }
  void Step(const StepContext&) override {}
};

/// Counts its lifecycle calls; throws from Step at step params.at (default never).
class Thrower : public Component {
 public:
  void Configure(const nlohmann::json& params) override {
    at_ = params.value("at", int64_t{-1});
    every_ = params.value("every", false);
  }
  void Start() override { ++starts; }
  void Step(const StepContext& context) override {
    ++steps;
    if (context.step == at_ || (every_ && context.step >= at_ && at_ >= 0)) {
      throw std::runtime_error("sensor unplugged");
    }
  }
  void Stop() override { ++stops; }
  int starts = 0;
  int steps = 0;
  int stops = 0;

 private:
  int64_t at_ = -1;
  bool every_ = false;
};

/// Waits in Step (up to timeout_ms, default 10 s) until `parties` Rendezvous components of its
/// `group` are inside their Step at the same time; records per step whether they met, and on which
/// thread it ran. With params.affine it asks to run on the pipeline's thread.
class Rendezvous : public Component {
 public:
  Rendezvous() : out_(AddOutput<Value>("out")) {}
  void Configure(const nlohmann::json& params) override {
    parties_ = params.value("parties", 2);
    timeout_ms_ = params.value("timeout_ms", 10000);
    affine_ = params.value("affine", false);
    group_ = &Group(params.value("group", std::string("g")));
  }
  bool thread_affine() const override { return affine_; }
  void Step(const StepContext& context) override {
    threads.push_back(std::this_thread::get_id());
    std::unique_lock<std::mutex> lock(group_->mutex);
    const int64_t round = context.step;
    if (++group_->arrived[round] == parties_) group_->met.notify_all();
    met.push_back(group_->met.wait_for(lock, std::chrono::milliseconds(timeout_ms_),
                                       [&] { return group_->arrived[round] >= parties_; }));
    out_.Emit(Value{static_cast<double>(context.step)});
  }
  std::vector<bool> met;
  std::vector<std::thread::id> threads;

 private:
  struct State {
    std::mutex mutex;
    std::condition_variable met;
    std::map<int64_t, int> arrived;
  };
  static State& Group(const std::string& name) {
    static std::mutex guard;
    static std::map<std::string, std::unique_ptr<State>> groups;
    std::lock_guard<std::mutex> lock(guard);
    auto& state = groups[name];
    if (!state) state = std::make_unique<State>();
    return *state;
  }
  Output<Value>& out_;
  int parties_ = 2;
  int timeout_ms_ = 10000;
  bool affine_ = false;
  State* group_ = nullptr;
};

inline ComponentRegistry MakeTestRegistry() {
  ComponentRegistry registry;
  registry.Register<Source>("test.source", "emits start + step");
  registry.Register<RandomSource>("test.random");
  registry.Register<Relay>("test.relay");
  registry.Register<Recorder>("test.recorder");
  registry.Register<RequiredSink>("test.required_sink");
  registry.Register<ImageSink>("test.image_sink");
  registry.Register<Thrower>("test.thrower");
  registry.Register<Rendezvous>("test.rendezvous");
  return registry;
}

}  // namespace saccade::runtime::testing
