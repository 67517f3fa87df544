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

}  // namespace saccade::app
