#pragma once
// Errors and always-on assertions shared by every saccade module.
//
// Bad user input (files, parameters, commands) throws an exception derived from
// saccade::Error whose message names what was wrong, where, and what was expected.
// Broken internal invariants are bugs: SACCADE_ASSERT reports them and aborts.

#include <stdexcept>
#include <string>

namespace saccade {

/// Base of every exception saccade throws for bad input.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// A parameter outside its valid range (e.g. fx <= 0). The message names the field and value.
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

/// A file that cannot be read or parsed. The message starts with "file:line: key:".
class FileError : public Error {
 public:
  /// `line` is 1-based; 0 when the error concerns the whole file.
  FileError(const std::string& file, int line, const std::string& key, const std::string& what);
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  const std::string& key() const { return key_; }

 private:
  std::string file_;
  int line_;
  std::string key_;
};

namespace internal {
[[noreturn]] void AssertionFailed(const char* condition, const char* file, int line,
                                  const std::string& message);
}  // namespace internal

}  // namespace saccade

/// Always-on check of an internal invariant (never of user input): aborts with a message.
#define SACCADE_ASSERT(condition, message)                                             \
  do {                                                                                 \
    if (!(condition)) {                                                                \
      ::saccade::internal::AssertionFailed(#condition, __FILE__, __LINE__, (message)); \
    }                                                                                  \
  } while (false)
