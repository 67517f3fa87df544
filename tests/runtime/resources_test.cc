// Shared resources (resources.h): named once in a pipeline or hardware file, loaded once by the
// pipeline, handed to every component typed; a bad file is reported at the line that names it.

#include "saccade/runtime/resources.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "runtime/test_components.h"
#include "saccade/runtime/pipeline.h"

namespace saccade::runtime {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

// A resource type of the tests' own, loaded as the kind "scene" (the one a pipeline file names
// at its top): a text file's first line, with a count of loads.
struct Note {
  std::string text;
};
int g_loads = 0;

ResourceLoader NoteLoader() {
  return ResourceLoader{typeid(Note), "Note", [](const std::string& path) {
                          std::ifstream in(path);
                          if (!in) throw FileError(path, 0, "", "cannot open the note");
                          auto note = std::make_shared<Note>();
                          std::getline(in, note->text);
                          ++g_loads;
                          return std::shared_ptr<const void>(std::move(note));
                        }};
}

// Records the note it was handed and the address, to show that every component gets one object.
class NoteReader : public Component {
 public:
  void Configure(const nlohmann::json& params) override {
    note_ = params.contains("note") ? resources().Load<Note>("scene", ResolvePath(params["note"]))
                                    : resources().Default<Note>("scene");
    if (!note_) throw InvalidArgument("no note");
  }
  void Step(const StepContext&) override {}
  std::shared_ptr<const Note> note_;
};

class ResourcesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("saccade_resources_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_ / "sub");
    Write("a.txt", "alpha\n");
    Write("b.txt", "beta\n");
    registry_ = testing::MakeTestRegistry();
    registry_.RegisterResource("scene", NoteLoader());
    registry_.Register<NoteReader>("test.note_reader");
    g_loads = 0;
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  // The Note of component `name` of `pipeline`.
  static const Note* NoteOf(const Pipeline& pipeline, const std::string& name) {
    return pipeline.Find<NoteReader>(name)->note_.get();
  }

  fs::path dir_;
  ComponentRegistry registry_;
};

TEST_F(ResourcesTest, LoadsOncePerCanonicalPathAndChecksKindAndType) {
  Resources resources({{"note", NoteLoader()}});
  const auto a = resources.Load<Note>("note", (dir_ / "a.txt").string());
  const auto again = resources.Load<Note>("note", (dir_ / "sub" / ".." / "a.txt").string());
  const auto b = resources.Load<Note>("note", (dir_ / "b.txt").string());
  EXPECT_EQ(a.get(), again.get());
  EXPECT_NE(a.get(), b.get());
  EXPECT_EQ(a->text, "alpha");
  EXPECT_EQ(g_loads, 2);
  EXPECT_EQ(resources.Default<Note>("note"), nullptr);
  try {
    resources.Load<Note>("mesh", (dir_ / "a.txt").string());
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("'mesh'"));
  }
  try {
    resources.Load<int>("note", (dir_ / "a.txt").string());
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("is a Note"));
  }
  EXPECT_THROW(resources.SetDefault("mesh", "x"), InvalidArgument);
}

TEST_F(ResourcesTest, APipelineLoadsItsResourceOnceForEveryComponent) {
  const std::string file = Write("loop.yaml", R"(scene: a.txt
components:
  - {name: first, type: test.note_reader}
  - {name: second, type: test.note_reader}
  - {name: other, type: test.note_reader, params: {note: b.txt}}
  - {name: same, type: test.note_reader, params: {note: sub/../a.txt}}
)");
  const Pipeline pipeline = Pipeline::LoadFile(file, registry_);
  EXPECT_EQ(NoteOf(pipeline, "first")->text, "alpha");
  EXPECT_EQ(NoteOf(pipeline, "first"), NoteOf(pipeline, "second"));
  EXPECT_EQ(NoteOf(pipeline, "first"), NoteOf(pipeline, "same"));
  EXPECT_EQ(NoteOf(pipeline, "other")->text, "beta");
  EXPECT_EQ(g_loads, 2);  // a.txt and b.txt, each once
  // Two pipelines share nothing: no static cache.
  const Pipeline second = Pipeline::LoadFile(file, registry_);
  EXPECT_NE(NoteOf(pipeline, "first"), NoteOf(second, "first"));
}

TEST_F(ResourcesTest, ThePipelinesOwnResourceWinsOverItsHardwareLinesFile) {
  Write("hardware.yaml", "scene: b.txt\ncomponents:\n  reader: {type: test.note_reader}\n");
  const std::string file = Write("loop.yaml", R"(scene: a.txt
hardware: hardware.yaml
components:
  - {name: reader}
  - {name: plain, type: test.note_reader}
)");
  const Pipeline pipeline = Pipeline::LoadFile(file, registry_);
  EXPECT_EQ(NoteOf(pipeline, "reader")->text, "alpha");
  EXPECT_EQ(NoteOf(pipeline, "plain")->text, "alpha");
  // Without a line of its own the pipeline takes its hardware file's.
  const std::string bare = Write("bare.yaml", R"(hardware: hardware.yaml
components:
  - {name: reader}
)");
  EXPECT_EQ(NoteOf(Pipeline::LoadFile(bare, registry_), "reader")->text, "beta");
}

TEST_F(ResourcesTest, AHardwareFileGivenInsteadOfThePipelinesLineWins) {
  Write("hardware.yaml", "scene: b.txt\ncomponents:\n  reader: {type: test.note_reader}\n");
  const std::string other =
      Write("other.yaml", "components:\n  reader: {type: test.note_reader}\n");
  const std::string file = Write("loop.yaml", R"(scene: a.txt
hardware: hardware.yaml
components:
  - {name: reader}
)");
  // As `--hardware FILE` gives it: its scene wins over the pipeline's line...
  const PipelineSpec spec = LoadPipelineFile(file, (dir_ / "hardware.yaml").string());
  EXPECT_EQ(spec.resources.at("scene").path, (dir_ / "b.txt").string());
  // ...and one that names no scene leaves the pipeline's.
  const PipelineSpec kept = LoadPipelineFile(file, other);
  EXPECT_EQ(kept.resources.at("scene").path, (dir_ / "a.txt").string());
}

TEST_F(ResourcesTest, AMissingFileIsReportedAtTheLineThatNamesIt) {
  const std::string file = Write("loop.yaml", R"(seed: 1
scene: missing.txt
components:
  - {name: first, type: test.note_reader}
)");
  try {
    Pipeline::LoadFile(file, registry_);
    FAIL();
  } catch (const FileError& e) {
    EXPECT_EQ(e.line(), 2) << e.what();
    EXPECT_EQ(e.key(), "scene") << e.what();
    EXPECT_THAT(e.what(), HasSubstr("missing.txt: cannot open the note"));
  }
  // A kind the registry cannot load.
  const std::string unknown = Write("unknown.yaml", R"(scene: a.txt
components:
  - {name: first, type: test.source}
)");
  try {
    Pipeline::LoadFile(unknown, testing::MakeTestRegistry());
    FAIL();
  } catch (const FileError& e) {
    EXPECT_EQ(e.line(), 1) << e.what();
    EXPECT_THAT(e.what(), HasSubstr("no resource of kind 'scene'"));
  }
}

}  // namespace
}  // namespace saccade::runtime
