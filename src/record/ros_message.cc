#include "saccade/record/ros_message.h"

#include <fmt/format.h>

#include <bit>
#include <cstring>
#include <map>
#include <optional>

#include "saccade/core/error.h"

namespace saccade::record {

namespace ros_message_detail {

enum class Kind { kBool, kInt, kUint, kFloat, kString, kMessage };

struct Field {
  std::string name;
  Kind kind = Kind::kInt;
  int size = 0;        // bytes of a number
  std::string type;    // kMessage: its full name "pkg/Type"
  bool array = false;  // T[] or T[N] or T[<=N]
  int fixed = -1;      // T[N]: N
  bool bytes = false;  // an array of 1-byte integers: a blob
};

using Definitions = std::map<std::string, std::vector<Field>>;

// `time` and `duration` fields: builtin_interfaces/Time's and Duration's layout.
constexpr char kBuiltinTime[] = "(time)";

// "pkg/msg/Type" or "pkg/Type" -> "pkg/Type".
std::string ShortName(const std::string& type) {
  const auto at = type.find("/msg/");
  return at == std::string::npos ? type : type.substr(0, at) + "/" + type.substr(at + 5);
}

std::string Trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  return s.substr(begin, s.find_last_not_of(" \t\r") - begin + 1);
}

// A primitive's kind and size; nullopt for a message type.
std::optional<std::pair<Kind, int>> Primitive(const std::string& type) {
  static const std::map<std::string, std::pair<Kind, int>> primitives = {
      {"bool", {Kind::kBool, 1}},      {"byte", {Kind::kUint, 1}},
      {"char", {Kind::kUint, 1}},      {"int8", {Kind::kInt, 1}},
      {"uint8", {Kind::kUint, 1}},     {"int16", {Kind::kInt, 2}},
      {"uint16", {Kind::kUint, 2}},    {"int32", {Kind::kInt, 4}},
      {"uint32", {Kind::kUint, 4}},    {"int64", {Kind::kInt, 8}},
      {"uint64", {Kind::kUint, 8}},    {"float32", {Kind::kFloat, 4}},
      {"float64", {Kind::kFloat, 8}},  {"string", {Kind::kString, 4}},
      {"wstring", {Kind::kString, 4}},
  };
  const auto bounded = type.find("<=");  // string<=N
  const auto found = primitives.find(bounded == std::string::npos ? type : type.substr(0, bounded));
  if (found == primitives.end()) return std::nullopt;
  return found->second;
}

Field ParseField(const std::string& line, const std::string& package, const std::string& where) {
  const auto space = line.find_first_of(" \t");
  if (space == std::string::npos) throw InvalidArgument(where + ": expected 'type name'");
  std::string type = line.substr(0, space);
  std::string rest = Trim(line.substr(space));
  Field f;
  f.name = rest.substr(0, rest.find_first_of(" \t"));
  if (const auto bracket = type.find('['); bracket != std::string::npos) {
    f.array = true;
    const std::string size = type.substr(bracket + 1, type.size() - bracket - 2);
    if (type.back() != ']') throw InvalidArgument(where + ": unclosed '[' in " + type);
    if (!size.empty() && size.rfind("<=", 0) != 0) {
      try {
        f.fixed = std::stoi(size);
      } catch (const std::exception&) {
        throw InvalidArgument(where + ": array size '" + size + "' is not a number");
      }
    }
    type.resize(bracket);
  }
  if (const auto primitive = Primitive(type)) {
    f.kind = primitive->first;
    f.size = primitive->second;
    f.bytes = f.array && f.size == 1 && f.kind != Kind::kBool;
  } else if (type == "time" || type == "duration") {
    // The builtins of ROS 1's syntax, as some tools still write ROS 2's Time and Duration.
    f.kind = Kind::kMessage;
    f.type = kBuiltinTime;
  } else {
    f.kind = Kind::kMessage;
    if (type == "Header") type = "std_msgs/Header";  // ROS 1's shorthand, still seen
    f.type = ShortName(type.find('/') == std::string::npos ? package + "/" + type : type);
  }
  return f;
}

// Every type of the definition text, by short name; the first section is `type`.
Definitions Parse(const std::string& type, const std::string& text) {
  Definitions definitions;
  std::string current = ShortName(type);
  std::vector<Field>* fields = &definitions[current];
  std::size_t start = 0;
  int line_number = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    std::string line = text.substr(start, end - start);
    start = end + 1;
    ++line_number;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    line = Trim(line);
    if (line.empty()) continue;
    if (line.find_first_not_of('=') == std::string::npos) continue;  // a separator
    if (line.rfind("MSG:", 0) == 0) {
      current = ShortName(Trim(line.substr(4)));
      fields = &definitions[current];
      continue;
    }
    const std::string where = fmt::format("{}: line {}", ShortName(type), line_number);
    // A constant ("uint8 DEBUG=10", "string NAME = 'x'") is not a field.
    const auto equals = line.find('=');
    if (equals != std::string::npos && line.find(' ') < equals) {
      const std::string before = Trim(line.substr(0, equals));
      if (before.find_first_of(" \t") != std::string::npos &&
          Trim(before.substr(before.find_first_of(" \t"))).find_first_of(" \t") ==
              std::string::npos) {
        continue;
      }
    }
    const std::string package = current.substr(0, current.find('/'));
    fields->push_back(ParseField(line, package, where));
  }
  Field sec, nanosec;
  sec.name = "sec";
  sec.size = 4;
  nanosec.name = "nanosec";
  nanosec.kind = Kind::kUint;
  nanosec.size = 4;
  definitions[kBuiltinTime] = {sec, nanosec};
  return definitions;
}

class Cursor {
 public:
  Cursor(std::span<const uint8_t> body, bool swap) : body_(body), swap_(swap) {}
  void Align(int n) {
    const std::size_t a = static_cast<std::size_t>(std::min(n, 8));
    pos_ = (pos_ + a - 1) / a * a;
  }
  std::span<const uint8_t> Take(std::size_t n, const std::string& what) {
    if (pos_ > body_.size() || n > body_.size() - pos_) {
      throw InvalidArgument(fmt::format("{} needs {} bytes at byte {}; the message has {}", what, n,
                                        pos_ + 4, body_.size() + 4));
    }
    const auto out = body_.subspan(pos_, n);
    pos_ += n;
    return out;
  }
  uint64_t Unsigned(int size, const std::string& what) {
    Align(size);
    const auto bytes = Take(static_cast<std::size_t>(size), what);
    uint64_t v = 0;
    for (int i = 0; i < size; ++i) {
      const int shift = swap_ ? (size - 1 - i) * 8 : i * 8;
      v |= static_cast<uint64_t>(bytes[i]) << shift;
    }
    return v;
  }
  uint32_t Length(const std::string& what) {
    const auto n = static_cast<uint32_t>(Unsigned(4, what + " (length)"));
    if (n > body_.size() - std::min(pos_, body_.size())) {
      throw InvalidArgument(
          fmt::format("{}: a length of {} at byte {}, beyond the message's {} "
                      "bytes",
                      what, n, pos_, body_.size() + 4));
    }
    return n;
  }

 private:
  std::span<const uint8_t> body_;
  bool swap_;
  std::size_t pos_ = 0;
};

}  // namespace ros_message_detail

using namespace ros_message_detail;  // NOLINT: this file's own helpers

struct RosMessageDecoder::Impl {
  std::string type;
  Definitions definitions;

  nlohmann::json One(const Field& f, Cursor& c, const std::string& path,
                     std::vector<std::span<const uint8_t>>* blobs, int depth) const;
  nlohmann::json Message(const std::string& type, Cursor& c, const std::string& path,
                         std::vector<std::span<const uint8_t>>* blobs, int depth) const {
    if (depth > 32) throw InvalidArgument(path + ": nested more than 32 deep");
    const auto found = definitions.find(type);
    nlohmann::json out = nlohmann::json::object();
    for (const Field& f : found->second) {
      const std::string where = path.empty() ? f.name : path + "." + f.name;
      if (!f.array) {
        out[f.name] = One(f, c, where, blobs, depth);
        continue;
      }
      const uint32_t n = f.fixed >= 0 ? static_cast<uint32_t>(f.fixed) : c.Length(where);
      if (f.bytes) {
        out[f.name] = {{"blob", blobs->size()}};
        blobs->push_back(c.Take(n, where));
        continue;
      }
      nlohmann::json items = nlohmann::json::array();
      for (uint32_t i = 0; i < n; ++i) {
        items.push_back(One(f, c, fmt::format("{}[{}]", where, i), blobs, depth));
      }
      out[f.name] = std::move(items);
    }
    return out;
  }
};

nlohmann::json RosMessageDecoder::Impl::One(const Field& f, Cursor& c, const std::string& path,
                                            std::vector<std::span<const uint8_t>>* blobs,
                                            int depth) const {
  switch (f.kind) {
    case Kind::kBool:
      return c.Unsigned(1, path) != 0;
    case Kind::kUint:
      return c.Unsigned(f.size, path);
    case Kind::kInt: {
      const uint64_t u = c.Unsigned(f.size, path);
      const int shift = 64 - 8 * f.size;
      return static_cast<int64_t>(u << shift) >> shift;  // sign-extended
    }
    case Kind::kFloat: {
      const uint64_t u = c.Unsigned(f.size, path);
      if (f.size == 4) return static_cast<double>(std::bit_cast<float>(static_cast<uint32_t>(u)));
      return std::bit_cast<double>(u);
    }
    case Kind::kString: {
      const uint32_t n = c.Length(path);
      const auto bytes = c.Take(n, path);
      std::string s(bytes.begin(), bytes.end());
      if (!s.empty() && s.back() == '\0') s.pop_back();  // CDR counts the terminating NUL
      return s;
    }
    case Kind::kMessage:
      return Message(f.type, c, path, blobs, depth + 1);
  }
  return nullptr;
}

RosMessageDecoder::RosMessageDecoder(const std::string& type, const std::string& definition)
    : impl_(std::make_unique<Impl>()) {
  impl_->type = ShortName(type);
  impl_->definitions = Parse(type, definition);
  for (const auto& [name, fields] : impl_->definitions) {
    for (const Field& f : fields) {
      if (f.kind == Kind::kMessage && !impl_->definitions.count(f.type)) {
        throw InvalidArgument(
            fmt::format("{}: field {} of {} has type {}, which the definition "
                        "does not define",
                        impl_->type, f.name, name, f.type));
      }
    }
  }
}

RosMessageDecoder::~RosMessageDecoder() = default;
RosMessageDecoder::RosMessageDecoder(RosMessageDecoder&&) noexcept = default;
RosMessageDecoder& RosMessageDecoder::operator=(RosMessageDecoder&&) noexcept = default;

nlohmann::json RosMessageDecoder::Decode(std::span<const uint8_t> cdr,
                                         std::vector<std::span<const uint8_t>>* blobs) const {
  if (cdr.size() < 4) {
    throw InvalidArgument(fmt::format("{}: {} bytes, shorter than the encapsulation header",
                                      impl_->type, cdr.size()));
  }
  const unsigned id = (unsigned{cdr[0]} << 8) | cdr[1];
  if (id != 0x0000 && id != 0x0001) {
    throw InvalidArgument(fmt::format(
        "{}: encapsulation 0x{:04x} is not plain CDR (0x0000 or 0x0001)", impl_->type, id));
  }
  const bool little = id == 0x0001;
  Cursor c(cdr.subspan(4), little != (std::endian::native == std::endian::little));
  try {
    return impl_->Message(impl_->type, c, "", blobs, 0);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(impl_->type + ": " + e.what());
  }
}

}  // namespace saccade::record
