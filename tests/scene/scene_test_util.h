#pragma once
// Helpers shared by the scene tests: a temporary folder, files in it, and error messages.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>

#include "saccade/core/error.h"
#include "saccade/scene/scene.h"

namespace saccade::scene::testing {

inline const std::string kSourceDir = SACCADE_SOURCE_DIR;
inline const std::string kAssets = kSourceDir + "/assets";
inline const std::string kPopeye = kSourceDir + "/robots/popeye.yaml";
inline const std::string kAssimpModels = "/usr/share/assimp/models";

/// A fresh folder under the system's temporary folder, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::temp_directory_path() /
            ("saccade_scene_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  /// Writes `text` to `name` in the folder; returns its path.
  std::filesystem::path Write(const std::string& name, const std::string& text) const {
    const std::filesystem::path file = path_ / name;
    std::filesystem::create_directories(file.parent_path());
    std::ofstream(file, std::ios::binary) << text;
    return file;
  }

 private:
  std::filesystem::path path_;
};

/// Replaces the first occurrence of `from` (which must exist) by `to`.
inline std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test bug: '" << from << "' not in the text";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

/// 1-based line of the first occurrence of `needle`.
inline int LineOf(const std::string& text, const std::string& needle) {
  const auto at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << "test bug: '" << needle << "' not in the text";
  if (at == std::string::npos) return -1;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
}

/// Loads scene text named "test.yaml" with paths relative to `base_dir`; returns the
/// FileError, failing the test when the load succeeds or throws anything else.
inline FileError LoadError(const std::string& text, const std::filesystem::path& base_dir) {
  try {
    Scene::FromYamlString(text, "test.yaml", base_dir);
  } catch (const FileError& error) {
    return error;
  } catch (const std::exception& error) {
    ADD_FAILURE() << "expected a FileError, got: " << error.what();
    return FileError("", 0, "", "");
  }
  ADD_FAILURE() << "expected a FileError, the scene loaded:\n" << text;
  return FileError("", 0, "", "");
}

/// Expects every one of `parts` in the message.
inline void ExpectMessageHas(const Error& error, std::initializer_list<std::string> parts) {
  const std::string message = error.what();
  for (const std::string& part : parts) {
    EXPECT_NE(message.find(part), std::string::npos)
        << "missing '" << part << "' in the message: " << message;
  }
}

}  // namespace saccade::scene::testing
