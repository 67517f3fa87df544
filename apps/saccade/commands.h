#pragma once
// The subcommands of `saccade`. Each Add* function registers one subcommand with its options
// and returns the function that runs it (returning the exit status); main() runs the one the
// user chose and turns saccade::Error into "saccade: error: ..." with status 1.

#include <CLI/CLI.hpp>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "saccade/head/head_model.h"
#include "saccade/head/joint_state.h"
#include "saccade/record/recorder.h"
#include "saccade/runtime/pipeline.h"

namespace saccade::app {

using Runner = std::function<int()>;

Runner AddFkCommand(CLI::App& app);
Runner AddIkCommand(CLI::App& app);
Runner AddCameraCommand(CLI::App& app);
Runner AddDemoCommand(CLI::App& app);
Runner AddRenderCommand(CLI::App& app);
Runner AddBenchCommand(CLI::App& app);
Runner AddGuiCommand(CLI::App& app);
Runner AddRunCommand(CLI::App& app);
Runner AddUrdfCommand(CLI::App& app);
Runner AddMcapCommand(CLI::App& app);
Runner AddExploreCommand(CLI::App& app);
Runner AddEmvaCommand(CLI::App& app);

// Shared helpers.
inline constexpr double kDegToRad = M_PI / 180.0;

/// A file shipped with saccade (robots/popeye.yaml, scenes/...): from the working directory if
/// it is there, else from the source tree saccade was built from, else from the installed
/// data (share/saccade).
std::string ShippedFile(const std::string& relative);

/// A head's joints from command-line values, one per joint in its order, radians (m for a
/// prismatic joint) or degrees. Throws InvalidArgument naming the joints when the count differs.
head::JointState JointsFromArgs(const head::HeadModel& head, const std::vector<double>& values,
                                bool degrees);

/// The --dds-* options of the commands that run a pipeline with topics (run, gui): they
/// override the pipeline file's `transport:` map (dds/transport.h).
struct DdsOverrides {
  std::optional<int> domain;
  std::string ns;
  std::string config;
  std::string interface;
  std::vector<std::string> peers;
  bool wall_stamps = false;  // --wall-stamps: transport.stamps wall
};
void AddDdsOptions(CLI::App* command, DdsOverrides& o);
/// The entries of the pipeline's `transport:` map that the options replace.
nlohmann::json DdsTransport(const DdsOverrides& o);
void ApplyDdsOverrides(const DdsOverrides& o, runtime::PipelineSpec& spec);

/// `--record FILE.mcap` and its tuning (record_commands.cc).
struct McapOptions {
  std::string path;  ///< "": no recording
  double chunk_s = 1.0;
  std::string compression = "zstd";
  int zstd_level = record::RecorderOptions{}.zstd_level;
  bool force = false;  ///< replace an existing file
};
bool IsMcapPath(const std::string& path);
/// The recorder's options for `--record FILE` and its tuning. Throws InvalidArgument (before
/// anything is written) for a name without .mcap, an existing file without `force`, a chunk
/// length <= 0, a zstd level out of range.
record::RecorderOptions RecorderOptionsFor(const McapOptions& o);
/// --record-chunk-s, --record-compression and --record-zstd-level.
void AddRecordTuning(CLI::App* command, McapOptions& o);

/// The "saccade" metadata of a recording: the command and the files it ran (empty ones left out).
std::map<std::string, std::string> RunMetadata(const std::string& command,
                                               const std::string& pipeline,
                                               const std::string& scene, const std::string& head,
                                               const std::string& hardware);

/// A run's MCAP recording (record/recorder.h) with, for rendered cameras, the scene's ground
/// truth on /saccade/ground_truth each step (JSON: every object's pose, every face's centre).
/// Its Metadata record "saccade" holds `metadata` plus the head and whether the cameras are
/// rendered or real.
class Recording {
 public:
  /// Throws InvalidArgument (before anything is written) for a name without .mcap, an existing
  /// file without `force`, a chunk length <= 0; FileError when it cannot be created.
  Recording(const McapOptions& o, runtime::Pipeline& pipeline,
            std::map<std::string, std::string> metadata);
  ~Recording();
  /// runtime::RunOptions::after_step.
  void AfterStep(const runtime::StepContext& context);
  /// Closes the file; returns a line for people ("record: N steps, ... MB in FILE").
  std::string Close();
  std::string file() const;
  uint64_t bytes() const;  ///< written so far

 private:
  struct Truth;
  std::unique_ptr<Truth> truth_;
  std::unique_ptr<record::PipelineRecorder> recorder_;
};

}  // namespace saccade::app
