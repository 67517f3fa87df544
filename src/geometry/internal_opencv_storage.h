#pragma once
// Private to calibration_io.cc: a small tree that both YAML (through yaml-cpp) and OpenCV
// FileStorage XML (through the tiny parser below) are read into, with 1-based line numbers
// for error messages, and a writer for the subset of FileStorage YAML/XML that calibration
// files use. OpenCV itself is not used (DESIGN.md layers): it is only the reference in tests.

#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace saccade::geometry::internal {

/// One value of a parsed file: a scalar, a map of keyed children or a sequence.
struct StorageNode {
  enum class Kind { kScalar, kMap, kSequence };
  Kind kind = Kind::kScalar;
  /// Line (1-based) where the value starts; 0 when unknown.
  int line = 0;
  /// The key of this node in its parent map, and the line of that key.
  std::string key;
  int key_line = 0;
  /// kScalar: the text, quotes and escapes already resolved (XML: entities decoded, quotes
  /// kept, whitespace kept).
  std::string text;
  /// "opencv-matrix" for YAML's !!opencv-matrix and XML's type_id="opencv-matrix", else empty.
  std::string type_id;
  /// kMap: children in file order (each with key set); kSequence: items.
  std::vector<StorageNode> children;

  /// The child with this key, nullptr if none. Throws FileError (naming `file`) when the
  /// key appears twice.
  const StorageNode* Find(std::string_view child_key, const std::string& file) const;
};

/// A whitespace-separated token of a scalar or an item of a sequence, with its line.
struct StorageToken {
  std::string_view text;
  int line = 0;
};

/// The items of a sequence, or the whitespace-separated tokens of a scalar (XML <data>).
/// Throws FileError (naming `file` and `key`) when a sequence item is not a scalar.
std::vector<StorageToken> Tokens(const StorageNode& node, const std::string& file,
                                 const std::string& key);

/// Parses YAML text (OpenCV's "%YAML:1.0" first line allowed) into a tree whose root is a
/// map. Throws FileError naming `file` and the line of a syntax error.
StorageNode ParseYamlStorage(const std::string& text, const std::string& file);

/// Parses OpenCV FileStorage XML: an optional <?xml ...?> declaration, comments, and one
/// <opencv_storage> root whose children are the keys. Elements with child elements are maps,
/// elements without are scalars; attributes other than type_id are ignored. Throws FileError
/// naming `file` and the line of a syntax error.
StorageNode ParseXmlStorage(const std::string& text, const std::string& file);

/// Formats a double with full precision (%.17g), always with a decimal point or exponent so
/// that FileStorage, yaml-cpp and PyYAML all read it back as the same real number.
std::string FormatDouble(double value);

/// Writes OpenCV FileStorage YAML ("%YAML:1.0", !!opencv-matrix) or XML (<opencv_storage>),
/// in the layout cv::FileStorage itself writes.
class OpenCvStorageWriter {
 public:
  explicit OpenCvStorageWriter(bool xml);

  void WriteInt(std::string_view key, long long value);
  /// `value` must not contain control characters (checked by the caller).
  void WriteString(std::string_view key, std::string_view value);
  /// A row-major rows x cols matrix of doubles (dt: d).
  void WriteMatrix(std::string_view key, int rows, int cols, std::span<const double> data);
  /// The whole file.
  std::string Finish();

 private:
  bool xml_;
  std::string out_;
};

/// `value` as a YAML double-quoted string (backslash and quote escaped).
std::string YamlQuoted(std::string_view value);

}  // namespace saccade::geometry::internal
