#pragma once
// What the pipeline and hardware fuzzers share: a registry of small components of their own
// (typed ports, declared parameters with ranges and choices, a required input, one that takes
// any params, under the hardware files' type names), and the checks of a parsed spec.
#include <cstdlib>
#include <set>
#include <string>
#include <vector>

#include "saccade/runtime/component.h"
#include "saccade/runtime/component_registry.h"
#include "saccade/runtime/message.h"
#include "saccade/runtime/pipeline.h"

namespace saccade_fuzz {

namespace rt = saccade::runtime;

inline void Check(bool condition) {
  if (!condition) std::abort();  // libFuzzer reports it with the input
}

// Emits a Value on "out"; parameters of each declared kind.
class Source : public rt::Component {
 public:
  Source() : out_(AddOutput<rt::Value>("out")) {
    DeclareParam("start", &start_, "first value").Range(-1e6, 1e6);
    DeclareParam("every", &every_, "steps between values").Range(1, 1000);
    DeclareParam("mode", &mode_, "how").Choices({"fast", "slow"});
    DeclareParam("on", &on_, "whether it emits");
    DeclareParam("names", &names_, "labels");
  }
  void Step(const rt::StepContext& context) override {
    if (on_ && context.step % every_ == 0) out_.Emit(rt::Value{start_});
  }

 private:
  rt::Output<rt::Value>& out_;
  double start_ = 0.0;
  int every_ = 1;
  std::string mode_ = "fast";
  bool on_ = true;
  std::vector<std::string> names_ = {"a"};
};

// Value in, Value and Text out.
class Relay : public rt::Component {
 public:
  Relay()
      : in_(AddInput<rt::Value>("in")),
        out_(AddOutput<rt::Value>("out")),
        text_(AddOutput<rt::Text>("text")) {}
  void Step(const rt::StepContext&) override {
    if (in_.has_value()) out_.Emit(in_.value());
    text_.Emit(rt::Text{"x"});
  }

 private:
  rt::Input<rt::Value>& in_;
  rt::Output<rt::Value>& out_;
  rt::Output<rt::Text>& text_;
};

// A required Value input and an optional Text input.
class Sink : public rt::Component {
 public:
  Sink() {
    AddInput<rt::Value>("in", /*required=*/true);
    AddInput<rt::Text>("note");
  }
  void Step(const rt::StepContext&) override {}
};

// Takes any params (a component that reads them itself), as the robot's components do under
// the hardware files' type names: Value inputs joints and command, outputs joints, left, right.
class Anything : public rt::Component {
 public:
  Anything()
      : joints_in_(AddInput<rt::Value>("joints")),
        joints_(AddOutput<rt::Value>("joints")),
        left_(AddOutput<rt::Value>("left")),
        right_(AddOutput<rt::Value>("right")) {
    AddInput<rt::Value>("command");
  }
  void Configure(const nlohmann::json&) override {}
  void Step(const rt::StepContext&) override {
    if (joints_in_.has_value()) joints_.Emit(joints_in_.value());
    left_.Emit(rt::Value{1.0});
    right_.Emit(rt::Value{2.0});
  }

 private:
  rt::Input<rt::Value>& joints_in_;
  rt::Output<rt::Value>& joints_;
  rt::Output<rt::Value>& left_;
  rt::Output<rt::Value>& right_;
};

inline const rt::ComponentRegistry& Registry() {
  static const rt::ComponentRegistry registry = [] {
    rt::ComponentRegistry r;
    r.Register<Source>("test.source");
    r.Register<Relay>("test.relay");
    r.Register<Sink>("test.sink");
    // The types the committed hardware files name, so that their seeds build.
    for (const char* type : {"sim.cameras", "sim.head", "hw.cameras", "hw.head"}) {
      r.Register<Anything>(type);
    }
    return r;
  }();
  return registry;
}

inline bool IsName(const std::string& name) {
  if (name.empty()) return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

// What the format promises of any spec ParsePipeline returns (pipeline.h).
inline void CheckSpec(const rt::PipelineSpec& spec) {
  Check(!spec.components.empty());
  Check(spec.components.size() <= static_cast<std::size_t>(rt::kMaxComponents));
  Check(spec.threads >= 0 && spec.threads <= rt::kMaxThreads);
  std::set<std::string> names;
  for (const rt::ComponentSpec& c : spec.components) {
    Check(IsName(c.name) && names.insert(c.name).second);
    Check(!c.type.empty());
    for (const rt::ConnectionSpec& in : c.inputs) {
      Check(in.delay == 0 || in.delay == 1);
      if (in.topic.empty()) {
        Check(IsName(in.from_component) && IsName(in.from_output));
      } else {  // another process's topic ({topic: NAME, ...}): no port of this pipeline
        Check(in.from_component.empty() && in.from_output.empty());
      }
    }
  }
}

// JSON text of a value that may hold NaN or invalid UTF-8 (YAML lets both through).
inline std::string Dump(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// Two parses of the same text agree.
inline void CheckSameSpec(const rt::PipelineSpec& a, const rt::PipelineSpec& b) {
  Check(a.components.size() == b.components.size() && a.seed == b.seed && a.threads == b.threads &&
        a.clock.steps == b.clock.steps && a.hardware_file == b.hardware_file);
  for (std::size_t i = 0; i < a.components.size(); ++i) {
    Check(a.components[i].name == b.components[i].name &&
          a.components[i].type == b.components[i].type &&
          // By text: a param may be NaN (free-form params are checked by the component).
          Dump(a.components[i].params) == Dump(b.components[i].params) &&
          a.components[i].inputs.size() == b.components[i].inputs.size() &&
          a.components[i].params_file == b.components[i].params_file);
  }
}

// Builds the spec with the fuzzers' registry; a built pipeline has the spec's components in
// order. Bad specs end in saccade::Error (caught here).
inline void CheckBuild(const rt::PipelineSpec& spec) {
  try {
    const rt::Pipeline pipeline = rt::Pipeline::Build(spec, Registry());
    Check(pipeline.components().size() == spec.components.size());
    for (std::size_t i = 0; i < spec.components.size(); ++i) {
      Check(pipeline.components()[i]->name() == spec.components[i].name);
    }
  } catch (const saccade::Error&) {
  }
}

}  // namespace saccade_fuzz
