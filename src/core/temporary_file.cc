#include "saccade/core/temporary_file.h"

#include <fmt/format.h>
#include <unistd.h>

#include <string>
#include <system_error>
#include <vector>

#include "saccade/core/error.h"

namespace saccade {
namespace {

constexpr std::string_view kMarker = ".tmp";

// True for one or more decimal digits and nothing else.
bool AllDigits(std::string_view text) {
  if (text.empty()) return false;
  for (const char c : text) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

}  // namespace

std::filesystem::path TemporaryPathFor(const std::filesystem::path& path, unsigned n) {
  return path.parent_path() /
         fmt::format(".{}{}{}_{}", path.filename().string(), kMarker, ::getpid(), n);
}

bool IsTemporaryFileName(std::string_view name) {
  if (name.size() < 2 || name.front() != '.') return false;
  const std::size_t marker = name.rfind(kMarker);
  if (marker == std::string_view::npos || marker < 2) return false;  // ".tmp..." names nothing
  const std::string_view tail = name.substr(marker + kMarker.size());
  const std::size_t underscore = tail.find('_');
  if (underscore == std::string_view::npos) return false;
  return AllDigits(tail.substr(0, underscore)) && AllDigits(tail.substr(underscore + 1));
}

int RemoveStaleTemporaries(const std::filesystem::path& folder) {
  std::error_code error;
  if (!std::filesystem::is_directory(folder, error)) return 0;
  const std::string own = fmt::format("{}{}_", kMarker, ::getpid());
  std::vector<std::filesystem::path> stale;
  try {
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
      const std::string name = entry.path().filename().string();
      std::error_code status_error;
      if (!IsTemporaryFileName(name) || !entry.is_regular_file(status_error)) continue;
      const std::size_t marker = name.rfind(kMarker);
      if (name.compare(marker, own.size(), own) == 0) continue;  // this process's, in progress
      stale.push_back(entry.path());
    }
  } catch (const std::filesystem::filesystem_error& e) {
    throw FileError(
        folder.string(), 0, "",
        fmt::format("RemoveStaleTemporaries: cannot list the folder: {}", e.code().message()));
  }
  for (const auto& path : stale) {
    if (!std::filesystem::remove(path, error) && error) {
      throw FileError(path.string(), 0, "",
                      fmt::format("RemoveStaleTemporaries: cannot remove a stale temporary: {}",
                                  error.message()));
    }
  }
  return static_cast<int>(stale.size());
}

}  // namespace saccade
