#include "core/internal_yaml.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <utility>

#include "saccade/core/error.h"

namespace saccade::internal {

Entry::Entry(YAML::Node node, std::string path, const std::string* file, int fallback_line)
    : node_(std::move(node)), path_(std::move(path)), file_(file), fallback_line_(fallback_line) {}

int Entry::line() const {
  if (!node_.IsDefined()) return fallback_line_;
  const YAML::Mark mark = node_.Mark();
  return mark.is_null() ? fallback_line_ : mark.line + 1;
}

void Entry::Fail(const std::string& what) const { throw FileError(*file_, line(), path_, what); }

std::string Entry::Describe() const {
  if (!node_.IsDefined()) return "nothing";
  switch (node_.Type()) {
    case YAML::NodeType::Null:
      return "nothing (null)";
    case YAML::NodeType::Scalar: {
      // Long scalars are cut: messages stay one readable line.
      constexpr std::size_t kMaxShown = 60;
      std::string text = node_.Scalar();
      if (text.size() > kMaxShown) text = text.substr(0, kMaxShown) + "...";
      return "'" + text + "'";
    }
    case YAML::NodeType::Sequence:
      return fmt::format("a list of {}", node_.size());
    case YAML::NodeType::Map:
      return "a map";
    default:
      return "nothing";
  }
}

void Entry::ExpectMap(const std::vector<std::string>& allowed, const char* what) const {
  if (!node_.IsMap()) Fail(std::string("expected ") + what + ", got " + Describe());
  std::set<std::string> seen;
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    const int key_line = it->first.Mark().is_null() ? line() : it->first.Mark().line + 1;
    if (!it->first.IsScalar()) {
      throw FileError(*file_, key_line, path_, "expected a key name, got a list or a map as key");
    }
    const std::string key = it->first.Scalar();
    bool known = false;
    std::string expected;
    for (const std::string& name : allowed) {
      known = known || key == name;
      expected += (expected.empty() ? "" : ", ") + name;
    }
    if (!known) {
      throw FileError(*file_, key_line, Join(key),
                      "unknown key '" + key + "'; expected one of: " + expected);
    }
    if (!seen.insert(key).second) {
      throw FileError(*file_, key_line, Join(key), "duplicate key '" + key + "'");
    }
  }
}

void Entry::ExpectMap(std::initializer_list<const char*> allowed, const char* what) const {
  std::vector<std::string> names;
  for (const char* name : allowed) names.emplace_back(name);
  ExpectMap(names, what);
}

bool Entry::Has(const char* key) const { return node_.IsMap() && node_[key].IsDefined(); }

Entry Entry::Get(const char* key) const {
  if (!Has(key)) Fail(std::string("missing key '") + key + "'");
  return Entry(node_[key], Join(key), file_, line());
}

std::optional<Entry> Entry::Find(const char* key) const {
  if (!Has(key)) return std::nullopt;
  return Entry(node_[key], Join(key), file_, line());
}

std::vector<Entry> Entry::AsSequence(const char* what) const {
  if (!node_.IsSequence()) Fail(std::string("expected a list of ") + what + ", got " + Describe());
  std::vector<Entry> entries;
  entries.reserve(node_.size());
  for (std::size_t i = 0; i < node_.size(); ++i) {
    entries.emplace_back(node_[i], fmt::format("{}[{}]", path_, i), file_, line());
  }
  return entries;
}

double Entry::AsDouble() const {
  if (!node_.IsScalar()) Fail("expected a number, got " + Describe());
  double value = 0.0;
  try {
    value = node_.as<double>();
  } catch (const YAML::Exception&) {
    Fail("expected a number, got " + Describe());
  }
  if (!std::isfinite(value)) Fail("expected a finite number, got " + Describe());
  return value;
}

double Entry::AsPositive() const {
  const double value = AsDouble();
  if (!(value > 0.0)) Fail(fmt::format("expected a positive number, got {}", value));
  return value;
}

double Entry::AsNonNegative() const {
  const double value = AsDouble();
  if (!(value >= 0.0)) Fail(fmt::format("expected a number >= 0, got {}", value));
  return value;
}

int64_t Entry::AsInteger(int64_t min, int64_t max) const {
  const std::string expected = fmt::format("expected an integer in [{}, {}]", min, max);
  if (!node_.IsScalar()) Fail(expected + ", got " + Describe());
  long long value = 0;
  try {
    value = node_.as<long long>();
  } catch (const YAML::Exception&) {
    Fail(expected + ", got " + Describe());
  }
  if (value < min || value > max) Fail(expected + ", got " + Describe());
  return value;
}

uint64_t Entry::AsUint64() const {
  const std::string expected =
      fmt::format("expected an integer in [0, {}]", std::numeric_limits<uint64_t>::max());
  if (!node_.IsScalar()) Fail(expected + ", got " + Describe());
  const std::string& text = node_.Scalar();
  const bool hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
  const char* first = text.data() + (hex ? 2 : 0);
  const char* last = text.data() + text.size();
  uint64_t value = 0;
  // from_chars takes no sign, no spaces and no prefix: anything else is left unparsed.
  const auto [end, ec] = std::from_chars(first, last, value, hex ? 16 : 10);
  if (ec != std::errc() || end != last || first == last) Fail(expected + ", got " + Describe());
  return value;
}

bool Entry::AsBool() const {
  if (!node_.IsScalar()) Fail("expected true or false, got " + Describe());
  bool value = false;
  try {
    value = node_.as<bool>();
  } catch (const YAML::Exception&) {
    Fail("expected true or false, got " + Describe());
  }
  return value;
}

std::string Entry::AsString() const {
  if (!node_.IsScalar()) Fail("expected a string, got " + Describe());
  return node_.Scalar();
}

std::string Entry::AsNonEmptyString() const {
  std::string value = AsString();
  if (value.empty()) Fail("expected a non-empty string, got ''");
  return value;
}

std::vector<double> Entry::AsDoubles(int size, const char* names) const {
  const std::string expected =
      size < 0 ? std::string("expected a list of numbers")
               : fmt::format("expected {} numbers{}{}", size, *names != '\0' ? " " : "", names);
  if (!node_.IsSequence()) Fail(expected + ", got " + Describe());
  if (size >= 0 && static_cast<int>(node_.size()) != size) {
    Fail(fmt::format("{}, got {}", expected, node_.size()));
  }
  std::vector<double> values;
  for (std::size_t i = 0; i < node_.size(); ++i) {
    values.push_back(Entry(node_[i], fmt::format("{}[{}]", path_, i), file_, line()).AsDouble());
  }
  return values;
}

std::array<double, 3> Entry::AsVector3(const char* names) const {
  const std::vector<double> v = AsDoubles(3, names);
  return {v[0], v[1], v[2]};
}

std::array<float, 4> Entry::AsColor(bool allow_alpha) const {
  const char* expected = allow_alpha ? "expected a colour [r, g, b] or [r, g, b, a], each in [0, 1]"
                                     : "expected a colour [r, g, b], each in [0, 1]";
  const bool length_ok =
      node_.IsSequence() && (node_.size() == 3 || (allow_alpha && node_.size() == 4));
  if (!length_ok) {
    Fail(fmt::format("{}, got {}", expected,
                     node_.IsSequence() ? fmt::format("{} numbers", node_.size()) : Describe()));
  }
  std::array<float, 4> color{0.0f, 0.0f, 0.0f, 1.0f};
  for (std::size_t i = 0; i < node_.size(); ++i) {
    const Entry channel(node_[i], fmt::format("{}[{}]", path_, i), file_, line());
    const double value = channel.AsDouble();
    if (value < 0.0 || value > 1.0) {
      channel.Fail(fmt::format("{}, got {}", expected, value));
    }
    color[i] = static_cast<float>(value);
  }
  return color;
}

std::string Entry::Join(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

YAML::Node ParseYaml(const std::string& text, const std::string& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& error) {
    throw FileError(source, error.mark.is_null() ? 0 : error.mark.line + 1, "",
                    "YAML syntax error: " + error.msg);
  }
}

std::string ReadConfigFile(const std::filesystem::path& path, const std::string& what) {
  const std::string name = path.string();
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status))
    throw FileError(name, 0, "", "cannot open the " + what + ": no such file");
  if (!std::filesystem::is_regular_file(status)) {
    throw FileError(name, 0, "",
                    fmt::format("not a regular file (a folder, device or pipe); "
                                "expected a {}",
                                what));
  }
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxConfigFileBytes) {
    throw FileError(name, 0, "",
                    fmt::format("the {} is {} bytes, more than the {} a configuration file may "
                                "have",
                                what, size, kMaxConfigFileBytes));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError(name, 0, "", "cannot open the " + what);
  std::string text;
  text.resize(static_cast<std::size_t>(ec ? 0 : size));
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) throw FileError(name, 0, "", "cannot read the " + what);
  text.resize(static_cast<std::size_t>(in.gcount()));
  return text;
}

}  // namespace saccade::internal
