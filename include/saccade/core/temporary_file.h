#pragma once
// The temporary files of saccade's atomic writes (WritePng, the calibration writers): a file is
// written beside its final path under a hidden name, then renamed over it, so a reader never
// sees half a file. A process killed between the two (SIGKILL, power loss) leaves the
// temporary behind; RemoveStaleTemporaries clears them when an output folder is reused.

#include <filesystem>
#include <string_view>

namespace saccade {

/// The temporary beside `path` that an atomic write of it goes through, for the `n`-th write of
/// this process: ".<name>.tmp<pid>_<n>" in the same folder ("out/left/.000007.png.tmp4242_3").
std::filesystem::path TemporaryPathFor(const std::filesystem::path& path, unsigned n);

/// Whether `name` (a file name, no folder) has the form TemporaryPathFor gives: '.', a
/// non-empty name, ".tmp", decimal digits (a process id), '_', decimal digits.
bool IsTemporaryFileName(std::string_view name);

/// Removes the temporaries that atomic writes of other processes left in `folder` (not its
/// subfolders), as when a render was killed; files of any other name, and this process's own
/// temporaries (writes in progress), stay. Returns how many were removed; 0 for a missing
/// folder. Throws FileError naming the file when one cannot be removed. Not safe to call while
/// another process still writes into `folder`.
int RemoveStaleTemporaries(const std::filesystem::path& folder);

}  // namespace saccade
