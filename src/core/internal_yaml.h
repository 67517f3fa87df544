#pragma once
// Private to saccade's modules (core, scene, runtime): a YAML node with its key path and file, so
// that every error names file, 1-based line and key path ("objects[2].pose.position"). Every
// accessor checks the node's type and value and throws saccade::FileError; none lets a YAML
// exception out.

#include <yaml-cpp/yaml.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

namespace saccade::internal {

class Entry {
 public:
  /// `file` must outlive the entry. `fallback_line` is used when the node has no mark
  /// (an implicit null, a missing key): usually the parent's line.
  Entry(YAML::Node node, std::string path, const std::string* file, int fallback_line = 0);

  const YAML::Node& node() const { return node_; }
  const std::string& path() const { return path_; }
  const std::string& file() const { return *file_; }
  int line() const;

  [[noreturn]] void Fail(const std::string& what) const;

  /// What the node is, for "expected X, got Y" messages.
  std::string Describe() const;

  bool IsNull() const { return !node_.IsDefined() || node_.IsNull(); }
  bool IsMap() const { return node_.IsMap(); }
  bool IsSequence() const { return node_.IsSequence(); }
  bool IsScalar() const { return node_.IsScalar(); }

  /// Checks that the node is a map whose keys are all in `allowed`, without duplicates.
  /// `what` names the map in the error ("an object", "a light").
  void ExpectMap(const std::vector<std::string>& allowed, const char* what = "a map") const;
  void ExpectMap(std::initializer_list<const char*> allowed, const char* what = "a map") const;

  bool Has(const char* key) const;
  Entry Get(const char* key) const;  ///< throws "missing key" naming the key
  std::optional<Entry> Find(const char* key) const;

  /// A sequence (any length, possibly empty); `what` names the entries ("objects").
  std::vector<Entry> AsSequence(const char* what) const;

  double AsDouble() const;       ///< finite
  double AsPositive() const;     ///< finite, > 0
  double AsNonNegative() const;  ///< finite, >= 0
  int64_t AsInteger(int64_t min, int64_t max) const;
  /// A non-negative integer up to 2^64 - 1, decimal or 0x-prefixed hexadecimal.
  uint64_t AsUint64() const;
  bool AsBool() const;
  std::string AsString() const;  ///< a scalar
  std::string AsNonEmptyString() const;
  /// `size` finite numbers (any number of them when `size` < 0); `names` says what they are
  /// in the message ("[x, y, z]").
  std::vector<double> AsDoubles(int size, const char* names = "") const;
  std::array<double, 3> AsVector3(const char* names = "[x, y, z]") const;
  /// A colour: [r, g, b] (alpha 1) or, when `allow_alpha`, [r, g, b, a]; each in [0, 1].
  std::array<float, 4> AsColor(bool allow_alpha) const;

 private:
  std::string Join(const std::string& key) const;

  YAML::Node node_;
  std::string path_;
  const std::string* file_;
  int fallback_line_;
};

/// Parses YAML text; a syntax error throws FileError with the line.
YAML::Node ParseYaml(const std::string& text, const std::string& source);

/// The largest configuration file (scene, head, pipeline, calibration) read whole: far above
/// any real one, far below what would exhaust memory.
inline constexpr std::uintmax_t kMaxConfigFileBytes = std::uintmax_t{64} << 20;

/// The whole text of a configuration file. `what` names it in errors ("head description").
/// Throws FileError (file, line 0) when it is missing, not a regular file (a folder, a device
/// such as /dev/zero, a pipe: none of them ends or fits), larger than kMaxConfigFileBytes, or
/// cannot be read.
std::string ReadConfigFile(const std::filesystem::path& path, const std::string& what);

}  // namespace saccade::internal
