// Component methods (seed section 5.4): one-to-one requests with a reply or an error, typed in
// the process and by name with JSON through the pipeline.
#include <gtest/gtest.h>

#include <string>

#include "saccade/runtime/bus.h"
#include "saccade/runtime/component.h"
#include "saccade/runtime/pipeline.h"

namespace saccade::runtime {
namespace {

/// Keeps a number; methods read it, add to it, and fail on request.
class Counter : public Component {
 public:
  Counter() {
    AddMethod<Empty, Value>(
        "get", [this](const Empty&) { return Value{total_}; }, "the total");
    AddMethod<Value, Value>(
        "add",
        [this](const Value& v) {
          if (v.value < 0) throw InvalidArgument("cannot add a negative number");
          total_ += v.value;
          return Value{total_};
        },
        "adds a non-negative number, replies with the total");
  }
  void Step(const StepContext&) override {}

 private:
  double total_ = 0.0;
};

Pipeline Load() {
  ComponentRegistry registry;
  registry.Register<Counter>("test.counter");
  return Pipeline::LoadString(
      "clock: {mode: simulated, step: 0.1, steps: 1}\n"
      "components:\n  - {name: counter, type: test.counter}\n",
      "m.yaml", registry);
}

TEST(ComponentMethods, TypedCallsInTheProcess) {
  Pipeline pipeline = Load();
  const Component& counter = *pipeline.Find("counter");
  ASSERT_EQ(counter.methods().size(), 2u);
  EXPECT_EQ(counter.methods()[1]->request_type(), "runtime.value");
  const Method<Value, Value>* add = counter.FindMethod<Value, Value>("add");
  ASSERT_NE(add, nullptr);
  EXPECT_EQ(add->Call(Value{2.5}).value, 2.5);
  EXPECT_EQ(add->Call(Value{1.0}).value, 3.5);
  // The wrong types: not found, rather than a bad cast.
  EXPECT_EQ((counter.FindMethod<Empty, Value>("add")), nullptr);
}

TEST(ComponentMethods, JsonCallsByNameThroughThePipeline) {
  Pipeline pipeline = Load();
  EXPECT_EQ(pipeline.Call("counter", "add", {{"value", 4}}), nlohmann::json({{"value", 4.0}}));
  EXPECT_EQ(pipeline.Call("counter", "get", nlohmann::json::object()),
            nlohmann::json({{"value", 4.0}}));
}

TEST(ComponentMethods, ErrorsNameTheMethodAndWhatWentWrong) {
  Pipeline pipeline = Load();
  const auto error = [&](const std::string& component, const std::string& method,
                         const nlohmann::json& request) {
    try {
      pipeline.Call(component, method, request);
    } catch (const MethodError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error("counter", "add", {{"value", -1}}),
            "method 'add': handler failed: cannot add a negative number");
  EXPECT_EQ(error("counter", "add", {{"value", "three"}}),
            "method 'add': bad request: runtime.value: field 'value': expected a number, got "
            "\"three\"");
  EXPECT_EQ(error("counter", "mul", {}),
            "method 'counter.mul': component 'counter' has no such method (it has: get, add)");
  EXPECT_EQ(error("nobody", "get", {}), "method 'nobody.get': no component named 'nobody'");
  // A failed call changes nothing.
  EXPECT_EQ(pipeline.Call("counter", "get", nullptr), nlohmann::json({{"value", 0.0}}));
}

TEST(ComponentMethods, NamesMustBeNewIdentifiers) {
  class Twice : public Component {
   public:
    explicit Twice(const std::string& second) {
      AddMethod<Empty, Empty>(
          "m", [](const Empty&) { return Empty{}; }, "");
      AddMethod<Empty, Empty>(
          second, [](const Empty&) { return Empty{}; }, "");
    }
    void Step(const StepContext&) override {}
  };
  EXPECT_THROW(Twice("m"), InvalidArgument);
  EXPECT_THROW(Twice("a b"), InvalidArgument);
  EXPECT_NO_THROW(Twice("n"));
}

}  // namespace
}  // namespace saccade::runtime
