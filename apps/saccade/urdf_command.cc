// urdf: writes a head's URDF (issue 42, item 5), for ROS tools.

#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>

#include "commands.h"
#include "saccade/core/error.h"
#include "saccade/core/temporary_file.h"
#include "saccade/head/head_model.h"
#include "saccade/head/urdf_export.h"

namespace saccade::app {
namespace {

namespace fs = std::filesystem;

// Writes `text` beside `path` under a temporary name and renames it over `path`: a reader never
// sees half a URDF, and a failure leaves no file behind.
void WriteAtomically(const fs::path& path, const std::string& text) {
  if (!path.has_filename() || fs::is_directory(path)) {
    throw FileError(path.string(), 0, "-o", "expected a file name, got a folder");
  }
  const fs::path temporary = TemporaryPathFor(path, 0);
  {
    std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
    if (!file) {
      throw FileError(
          path.string(), 0, "-o",
          fmt::format("cannot create {}: {}", temporary.string(), std::strerror(errno)));
    }
    file << text;
    file.close();
    if (!file) {
      std::error_code ignored;
      fs::remove(temporary, ignored);
      throw FileError(path.string(), 0, "-o", "write failed");
    }
  }
  std::error_code error;
  fs::rename(temporary, path, error);
  if (error) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw FileError(path.string(), 0, "-o", "cannot replace the file: " + error.message());
  }
}

int RunUrdf(const std::string& head_path, const std::string& out) {
  if (!fs::is_regular_file(head_path)) {
    throw FileError(head_path, 0, "--head", "the head file does not exist");
  }
  const head::HeadModel head = head::HeadModel::FromFile(head_path);
  const head::UrdfExport exported = head::ExportUrdf(head);
  for (const std::string& warning : exported.warnings) {
    std::fprintf(stderr, "saccade: warning: %s: %s\n", head_path.c_str(), warning.c_str());
  }
  if (out.empty()) {
    std::cout << exported.xml << std::flush;
  } else {
    WriteAtomically(out, exported.xml);
  }
  return 0;
}

}  // namespace

Runner AddUrdfCommand(CLI::App& app) {
  struct Options {
    std::string head = ShippedFile("robots/popeye.yaml");
    std::string out;
  };
  auto o = std::make_shared<Options>();
  auto* urdf = app.add_subcommand(
      "urdf",
      "Write a head's URDF for ROS tools (robot_state_publisher, RViz, Gazebo). A head file that "
      "names a URDF (`urdf:`) gets that file's text, unchanged and nothing else. A legacy head "
      "(robots/popeye.yaml) gets its kinematic tree: links, joints with their limits and "
      "velocities, and a Gazebo camera per eye (<sensor type=\"camera\"> named left_camera and "
      "right_camera), no visuals. The head's pose in the world, accelerations, servos and "
      "fixation rule are not URDF's: a head file gives them beside it (robots/humanoid.yaml). "
      "A camera Gazebo cannot express exactly (fx != fy, off-centre principal point, skew, "
      "fisheye, k4..k6) is written with the nearest values and a warning on stderr.");
  urdf->add_option("--head", o->head, "Head file (YAML), either format")->capture_default_str();
  urdf->add_option("-o,--out", o->out,
                   "The URDF file to write (atomically: a temporary beside it, renamed); "
                   "standard output without it");
  return [o] { return RunUrdf(o->head, o->out); };
}

}  // namespace saccade::app
