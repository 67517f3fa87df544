#include "saccade/core/error.h"

#include <cstdio>
#include <cstdlib>

namespace saccade {
namespace {
std::string FileMessage(const std::string& file, int line, const std::string& key,
                        const std::string& what) {
  std::string message = file;
  if (line > 0) message += ":" + std::to_string(line);
  message += ": ";
  if (!key.empty()) message += key + ": ";
  return message + what;
}
}  // namespace

FileError::FileError(const std::string& file, int line, const std::string& key,
                     const std::string& what)
    : Error(FileMessage(file, line, key, what)), file_(file), line_(line), key_(key) {}

namespace internal {
void AssertionFailed(const char* condition, const char* file, int line,
                     const std::string& message) {
  std::fprintf(stderr, "saccade internal error at %s:%d: %s (%s)\n", file, line, message.c_str(),
               condition);
  std::abort();
}
}  // namespace internal
}  // namespace saccade
