#pragma once
// A folder for one test process's files under the system's temporary folder,
// saccade_<program>_<pid>: made on first use and removed with everything in it when the process
// that made it exits. A forked child that exits leaves it to its parent. Tests that wrote their
// files to a per-process folder and never removed it left 45 MB a run of the recorder's test in
// /tmp, and CI's disk is shared.
#include <errno.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace saccade::testing_helpers {

inline const std::filesystem::path& ScratchDir() {
  struct Dir {
    std::filesystem::path path;
    pid_t owner = ::getpid();
    Dir()
        : path(std::filesystem::temp_directory_path() /
               ("saccade_" + std::string(program_invocation_short_name) + "_" +
                std::to_string(::getpid()))) {
      std::filesystem::remove_all(path);
      std::filesystem::create_directories(path);
    }
    ~Dir() {
      if (::getpid() != owner) return;
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Dir dir;
  return dir.path;
}

/// `name` in ScratchDir(): a file's path, its folder made.
inline std::filesystem::path ScratchFile(const std::string& name) {
  const std::filesystem::path file = ScratchDir() / name;
  std::filesystem::create_directories(file.parent_path());
  return file;
}

/// A fresh (emptied) folder `name` in ScratchDir().
inline std::filesystem::path FreshScratchDir(const std::string& name) {
  const std::filesystem::path dir = ScratchDir() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace saccade::testing_helpers
