// Pipeline files: what a valid file gives, and the message of every kind of bad input (file,
// line, key and the offending name).

#include "saccade/runtime/pipeline.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "runtime/test_components.h"

namespace saccade::runtime {
namespace {

using testing::MakeTestRegistry;

constexpr const char* kFile = "loop.yaml";

// 1-based line of the first line containing `needle`.
int LineOf(const std::string& text, const std::string& needle) {
  const std::size_t at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  int line = 1;
  for (std::size_t i = 0; i < at; ++i) line += text[i] == '\n';
  return line;
}

// The message of the FileError that loading `text` throws ("" when none).
std::string LoadError(const std::string& text) {
  const ComponentRegistry registry = MakeTestRegistry();
  try {
    Pipeline::LoadString(text, kFile, registry);
  } catch (const FileError& error) {
    return error.what();
  }
  ADD_FAILURE() << "no FileError for:\n" << text;
  return "";
}

// Checks that `message` starts with "loop.yaml:<line>: <key>: " and holds every part.
void ExpectError(const std::string& message, int line, const std::string& key,
                 std::initializer_list<std::string> parts) {
  const std::string prefix = std::string(kFile) + ":" + std::to_string(line) + ": " + key + ": ";
  EXPECT_EQ(message.rfind(prefix, 0), 0u) << "expected prefix '" << prefix << "' in: " << message;
  for (const std::string& part : parts) {
    EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
  }
}

const std::string kValid = R"(clock: {mode: simulated, step: 0.5, steps: 4}
seed: 7
on_error: continue
components:
  - name: source
    type: test.source
    params: {start: 10}
  - name: relay
    type: test.relay
    inputs:
      in: source.out
  - name: recorder
    type: test.recorder
    inputs:
      in: {from: relay.out, delay: 1}
)";

TEST(PipelineLoaderTest, ValidFileGivesComponentsInOrder) {
  const ComponentRegistry registry = MakeTestRegistry();
  const Pipeline pipeline = Pipeline::LoadString(kValid, kFile, registry);
  const PipelineSpec& spec = pipeline.spec();
  EXPECT_EQ(spec.clock.mode, ClockMode::kSimulated);
  EXPECT_EQ(spec.clock.step, 0.5);
  EXPECT_EQ(spec.clock.steps, 4);
  EXPECT_EQ(spec.seed, 7u);
  EXPECT_EQ(spec.on_error, OnError::kContinue);
  ASSERT_EQ(pipeline.components().size(), 3u);
  EXPECT_EQ(pipeline.components()[0]->name(), "source");
  EXPECT_EQ(pipeline.components()[2]->name(), "recorder");
  EXPECT_EQ(spec.components[0].params, (nlohmann::json{{"start", 10}}));
  ASSERT_EQ(spec.components[2].inputs.size(), 1u);
  EXPECT_EQ(spec.components[2].inputs[0].from_component, "relay");
  EXPECT_EQ(spec.components[2].inputs[0].from_output, "out");
  EXPECT_EQ(spec.components[2].inputs[0].delay, 1);
  EXPECT_NE(pipeline.Find<testing::Recorder>("recorder"), nullptr);
  EXPECT_EQ(pipeline.Find<testing::Recorder>("source"), nullptr);
  EXPECT_EQ(pipeline.Find("nobody"), nullptr);
  EXPECT_NE(pipeline.components()[0]->seed(), pipeline.components()[1]->seed());
}

TEST(PipelineLoaderTest, RealtimeClockAndParamsAsJson) {
  const std::string text = R"(clock: {mode: realtime, rate_hz: 50}
components:
  - name: source
    type: test.source
    params: {start: 1.5, label: "12", list: [1, two, true], nested: {a: ~}}
)";
  const PipelineSpec spec = ParsePipeline(text, kFile);
  EXPECT_EQ(spec.clock.mode, ClockMode::kRealtime);
  EXPECT_EQ(spec.clock.rate_hz, 50.0);
  EXPECT_EQ(spec.on_error, OnError::kStop);
  EXPECT_EQ(
      spec.components[0].params,
      nlohmann::json::parse(
          R"({"start": 1.5, "label": "12", "list": [1, "two", true], "nested": {"a": null}})"));
}

TEST(PipelineLoaderTest, LoadsFromFile) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / "saccade_runtime_pipeline_test.yaml";
  std::ofstream(path) << kValid;
  const ComponentRegistry registry = MakeTestRegistry();
  EXPECT_EQ(Pipeline::LoadFile(path.string(), registry).components().size(), 3u);
  std::filesystem::remove(path);
  EXPECT_THROW(LoadPipelineFile(path.string()), FileError);
}

TEST(PipelineLoaderTest, UnknownComponentTypeListsKnownTypes) {
  const std::string text = R"(components:
  - name: detector
    type: vision.faces
)";
  ExpectError(LoadError(text), 3, "components[0].type",
              {"unknown component type 'vision.faces'", "detector",
               "known types: test.image_sink, test.random, test.recorder"});
}

TEST(PipelineLoaderTest, TooManyComponentsAreRefusedBeforeAnyIsBuilt) {
  std::string text = "components:\n";
  for (int i = 0; i <= kMaxComponents; ++i) {
    text += "  - {name: c" + std::to_string(i) + ", type: test.source}\n";
  }
  const std::string error = LoadError(text);
  EXPECT_NE(error.find("loop.yaml:2: components: 1001 components, more than the 1000"),
            std::string::npos)
      << error;
}

TEST(PipelineLoaderTest, DuplicateComponentNameRejected) {
  const std::string text = R"(components:
  - name: source
    type: test.source
  - name: source
    type: test.relay
)";
  ExpectError(LoadError(text), 4, "components[1].name",
              {"duplicate component name 'source'", "first at line 2"});
}

TEST(PipelineLoaderTest, UnknownComponentInConnectionRejected) {
  const std::string text = R"(components:
  - name: source
    type: test.source
  - name: recorder
    type: test.recorder
    inputs:
      in: camera.out
)";
  ExpectError(LoadError(text), LineOf(text, "in: camera"), "components[1].inputs.in",
              {"unknown component 'camera'", "camera.out", "components: source, recorder"});
}

TEST(PipelineLoaderTest, UnknownOutputRejected) {
  const std::string text = R"(components:
  - name: source
    type: test.source
  - name: recorder
    type: test.recorder
    inputs:
      in: source.left
)";
  ExpectError(LoadError(text), LineOf(text, "in: source"), "components[1].inputs.in",
              {"component 'source' (test.source) has no output 'left'",
               "its outputs: out (runtime.value)"});
}

TEST(PipelineLoaderTest, UnknownInputRejected) {
  const std::string text = R"(components:
  - name: source
    type: test.source
  - name: recorder
    type: test.recorder
    inputs:
      image: source.out
)";
  ExpectError(LoadError(text), LineOf(text, "image:"), "components[1].inputs.image",
              {"component 'recorder' (test.recorder) has no input 'image'",
               "its inputs: in (runtime.value)"});
}

TEST(PipelineLoaderTest, TypeMismatchNamesBothTypes) {
  const std::string text = R"(components:
  - name: source
    type: test.source
  - name: sink
    type: test.image_sink
    inputs:
      image: source.out
)";
  ExpectError(
      LoadError(text), LineOf(text, "image:"), "components[1].inputs.image",
      {"type mismatch", "'source.out' sends runtime.value", "'sink.image' expects runtime.image"});
}

TEST(PipelineLoaderTest, InputConnectedTwiceRejected) {
  const std::string text = R"(components:
  - name: a
    type: test.source
  - name: b
    type: test.source
  - name: recorder
    type: test.recorder
    inputs:
      in: a.out
      in: b.out
)";
  ExpectError(LoadError(text), LineOf(text, "in: b.out"), "components[2].inputs.in",
              {"input 'in' is connected twice"});
}

TEST(PipelineLoaderTest, RequiredInputLeftUnconnectedRejected) {
  const std::string text = R"(components:
  - name: source
    type: test.source
  - name: sink
    type: test.required_sink
)";
  ExpectError(LoadError(text), 4, "components[1].inputs",
              {"required input 'in' (runtime.value) of component 'sink' (test.required_sink) "
               "is not connected"});
}

const std::string kCycle = R"(clock: {mode: simulated, step: 1, steps: 3}
components:
  - name: source
    type: test.source
  - name: first
    type: test.relay
    inputs:
      in: second.out
  - name: second
    type: test.relay
    inputs:
      in: first.out
  - name: recorder
    type: test.recorder
    inputs:
      in: second.out
)";

TEST(PipelineLoaderTest, CycleWithoutDelayNamesItsComponents) {
  ExpectError(LoadError(kCycle), LineOf(kCycle, "in: second.out"), "components[1].inputs.in",
              {"cycle: first -> second -> first", "delay: 1"});
}

TEST(PipelineLoaderTest, SelfLoopWithoutDelayRejected) {
  const std::string text = R"(components:
  - name: loop
    type: test.relay
    inputs:
      in: loop.out
)";
  ExpectError(LoadError(text), 5, "components[0].inputs.in", {"cycle: loop -> loop"});
}

TEST(PipelineLoaderTest, ConnectionFromLaterComponentWithoutDelayRejected) {
  const std::string text = R"(components:
  - name: recorder
    type: test.recorder
    inputs:
      in: source.out
  - name: source
    type: test.source
)";
  ExpectError(LoadError(text), 5, "components[0].inputs.in",
              {"'source' runs after 'recorder'", "delay: 1"});
}

TEST(PipelineLoaderTest, CycleWithDelayAccepted) {
  std::string text = kCycle;
  text.replace(text.find("in: second.out"), 14, "in: {from: second.out, delay: 1}");
  const ComponentRegistry registry = MakeTestRegistry();
  EXPECT_NO_THROW(Pipeline::LoadString(text, kFile, registry));
}

TEST(PipelineLoaderTest, ShapeErrorsNameLineAndKey) {
  struct Case {
    std::string text;
    int line;
    std::string key;
    std::string part;
  };
  const Case cases[] = {
      {"components: []\n", 1, "components", "at least one component"},
      {"clock: {mode: fast}\ncomponents: [{name: a, type: test.source}]\n", 1, "clock.mode",
       "expected simulated or realtime, got 'fast'"},
      {"clock: {mode: simulated, step: -1}\ncomponents: [{name: a, type: test.source}]\n", 1,
       "clock.step", "expected a positive number"},
      {"clock: {mode: simulated, rate_hz: 5}\ncomponents: [{name: a, type: test.source}]\n", 1,
       "clock.rate_hz", "'rate_hz' is for mode realtime"},
      {"on_error: ignore\ncomponents: [{name: a, type: test.source}]\n", 1, "on_error",
       "expected stop or continue, got 'ignore'"},
      {"seed: -3\ncomponents: [{name: a, type: test.source}]\n", 1, "seed",
       "expected an integer in [0, "},
      {"threads: 65\ncomponents: [{name: a, type: test.source}]\n", 1, "threads",
       "expected an integer in [0, 64]"},
      {"components:\n  - name: a.b\n    type: test.source\n", 2, "components[0].name", "no dots"},
      {"components:\n  - name: a\n    kind: test.source\n", 3, "components[0].kind",
       "unknown key 'kind'"},
      {"components:\n  - name: a\n    type: test.recorder\n    inputs: {in: source}\n", 4,
       "components[0].inputs.in", "expected 'component.output', got 'source'"},
      {"components:\n  - name: a\n    type: test.recorder\n    inputs:\n      in: {from: a.out, "
       "delay: 2}\n",
       5, "components[0].inputs.in.delay", "expected an integer in [0, 1]"},
      {"components:\n  - name: a\n    type: test.source\n    params: [1, 2]\n", 4,
       "components[0].params", "expected a map of parameters"},
      {"components:\n  - name: a\n    type: test.source\n    params: {start: high}\n", 4,
       "components[0].params", "component 'a' (test.source): 'start' must be a number"},
      {"components:\n  - name: a\n    type: test.source\n  - name: [x\n", 4, "",
       "YAML syntax error"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    const std::string message = LoadError(c.text);
    if (c.key.empty()) {
      EXPECT_EQ(message.rfind(std::string(kFile) + ":", 0), 0u) << message;
      EXPECT_NE(message.find(c.part), std::string::npos) << message;
    } else {
      ExpectError(message, c.line, c.key, {c.part});
    }
  }
}

TEST(ComponentRegistryTest, DuplicateTypeAndUnknownTypeRejected) {
  ComponentRegistry registry = MakeTestRegistry();
  EXPECT_THROW(registry.Register<testing::Source>("test.source"), InvalidArgument);
  EXPECT_TRUE(registry.Has("test.source"));
  EXPECT_EQ(registry.Description("test.source"), "emits start + step");
  try {
    registry.Create("nope");
    FAIL() << "no exception";
  } catch (const InvalidArgument& error) {
    EXPECT_NE(std::string(error.what()).find("unknown component type 'nope'"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("test.thrower"), std::string::npos);
  }
}

TEST(ComponentTest, DuplicatePortNameRejected) {
  class Twice : public Component {
   public:
    Twice() {
      AddOutput<Value>("out");
      AddOutput<Text>("out");
    }
    void Step(const StepContext&) override {}
  };
  EXPECT_THROW(Twice(), InvalidArgument);
}

TEST(ComponentSeedTest, DependsOnSeedAndNameAndIsFixed) {
  EXPECT_EQ(ComponentSeed(1, "cameras"), ComponentSeed(1, "cameras"));
  EXPECT_NE(ComponentSeed(1, "cameras"), ComponentSeed(2, "cameras"));
  EXPECT_NE(ComponentSeed(1, "cameras"), ComponentSeed(1, "detector"));
}

}  // namespace
}  // namespace saccade::runtime

namespace saccade::runtime {
namespace {

// A folder with a pipeline and hardware files, removed at the end.
class HardwareFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("saccade_hardware_test_" +
            std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_ / "pipelines");
    std::filesystem::create_directories(dir_ / "hardware");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& text) {
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }
  std::filesystem::path dir_;
};

const std::string kPipelineWithHardware = R"(clock: {mode: simulated, step: 0.5, steps: 3}
hardware: ../hardware/one.yaml
components:
  - name: source
  - name: recorder
    type: test.recorder
    inputs: {in: source.out}
)";

TEST_F(HardwareFileTest, ComponentsWithoutTypeComeFromTheHardwareFile) {
  Write("hardware/one.yaml", "components:\n  source: {type: test.source, params: {start: 100}}\n");
  Write("hardware/two.yaml",
        "components:\n  source:\n    type: test.source\n    params: {start: 7}\n");
  const std::string pipeline = Write("pipelines/p.yaml", kPipelineWithHardware);
  const ComponentRegistry registry = MakeTestRegistry();

  const PipelineSpec spec = LoadPipelineFile(pipeline);
  EXPECT_EQ(spec.hardware_file, (dir_ / "pipelines/../hardware/one.yaml").string());
  EXPECT_EQ(spec.components[0].type, "test.source");
  EXPECT_EQ(spec.components[0].params, (nlohmann::json{{"start", 100}}));
  EXPECT_EQ(spec.components[0].params_file, spec.hardware_file);
  EXPECT_EQ(spec.components[1].params_file, "");

  // The one line to switch: another hardware file, from the command line.
  const std::string two = (dir_ / "hardware/two.yaml").string();
  const PipelineSpec other = LoadPipelineFile(pipeline, two);
  EXPECT_EQ(other.hardware_file, two);
  EXPECT_EQ(other.components[0].params, (nlohmann::json{{"start", 7}}));
  EXPECT_EQ(other.components[0].params_line, 4);
  Pipeline built = Pipeline::Build(other, registry);
  EXPECT_NE(built.Find<testing::Source>("source"), nullptr);
  // Relative paths in a hardware component's params resolve against the hardware file.
  EXPECT_EQ(built.Find("source")->ResolvePath("x.yaml"), (dir_ / "hardware/x.yaml").string());
  EXPECT_EQ(built.Find("recorder")->ResolvePath("x.yaml"), (dir_ / "pipelines/x.yaml").string());
}

TEST_F(HardwareFileTest, MismatchesAndBadFilesAreNamed) {
  const ComponentRegistry registry = MakeTestRegistry();
  const auto error = [&](const std::string& pipeline, const std::string& hardware = "") {
    try {
      Pipeline::Build(LoadPipelineFile(pipeline, hardware), registry);
    } catch (const FileError& e) {
      return std::string(e.what());
    }
    ADD_FAILURE() << "no FileError";
    return std::string();
  };
  const auto expect = [](const std::string& message, const std::string& part) {
    EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
  };
  const std::string pipeline = Write("pipelines/p.yaml", kPipelineWithHardware);

  // Missing hardware file: the pipeline's line names it.
  expect(error(pipeline), "p.yaml:2: hardware: ");
  expect(error(pipeline), "cannot open the hardware file");
  // A component the hardware file lacks, and one the pipeline lacks.
  Write("hardware/one.yaml", "components:\n  camera: {type: test.source}\n");
  expect(error(pipeline),
         "p.yaml:4: components[0]: component 'source' has no type, and the "
         "hardware file");
  Write("hardware/one.yaml",
        "components:\n  source: {type: test.source}\n  head: {type: test.relay}\n");
  expect(error(pipeline),
         "one.yaml:3: components.head: the hardware file defines 'head' but the "
         "pipeline");
  // A bad type or bad params name the hardware file's line.
  Write("hardware/one.yaml", "components:\n  source: {type: test.nope}\n");
  expect(error(pipeline), "one.yaml:2: components.source.type: unknown component type 'test.nope'");
  Write("hardware/one.yaml",
        "components:\n  source:\n    type: test.source\n    params: {start: x}\n");
  expect(error(pipeline),
         "one.yaml:4: components.source.params: component 'source' (test.source): "
         "'start' must be a number");
  Write("hardware/one.yaml", "components:\n  source: {type: test.source, inputs: {}}\n");
  expect(error(pipeline), "one.yaml:2: components.source.inputs: unknown key 'inputs'");
  Write("hardware/one.yaml", "parts: {}\n");
  expect(error(pipeline), "one.yaml:1: parts: unknown key 'parts'");
  // Both the pipeline and the hardware file typing a component.
  Write("hardware/one.yaml",
        "components:\n  recorder: {type: test.recorder}\n  source: {type: test.source}\n");
  expect(error(pipeline),
         "p.yaml:6: components[1].type: component 'recorder' is in the hardware "
         "file");
  // No hardware file at all.
  const std::string plain = Write("pipelines/plain.yaml", "components:\n  - name: source\n");
  expect(error(plain),
         "plain.yaml:2: components[0]: component 'source' has no type (and the "
         "pipeline names no hardware file");
  expect(error(plain, (dir_ / "hardware/none.yaml").string()),
         "none.yaml: cannot open the hardware file");
}

}  // namespace
}  // namespace saccade::runtime
