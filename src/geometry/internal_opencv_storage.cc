#include "internal_opencv_storage.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>

#include "saccade/core/error.h"

namespace saccade::geometry::internal {
namespace {

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";
constexpr std::string_view kOpenCvMatrix = "opencv-matrix";
// Deeper nesting than any calibration file has; bounds the recursion on hostile input.
constexpr int kMaxDepth = 64;

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

std::string_view KindName(StorageNode::Kind kind) {
  switch (kind) {
    case StorageNode::Kind::kScalar:
      return "a scalar";
    case StorageNode::Kind::kMap:
      return "a map";
    case StorageNode::Kind::kSequence:
      return "a sequence";
  }
  return "?";
}

// ---------------------------------------------------------------------------------------
// YAML through yaml-cpp.

int MarkLine(const YAML::Mark& mark) { return mark.line >= 0 ? mark.line + 1 : 0; }

StorageNode ConvertYaml(const YAML::Node& node, const std::string& file, int depth) {
  StorageNode out;
  out.line = MarkLine(node.Mark());
  if (depth > kMaxDepth) throw FileError(file, out.line, "", "nesting too deep");
  if (node.Tag().ends_with(kOpenCvMatrix)) out.type_id = std::string(kOpenCvMatrix);
  switch (node.Type()) {
    case YAML::NodeType::Scalar:
      out.text = node.Scalar();
      break;
    case YAML::NodeType::Sequence:
      out.kind = StorageNode::Kind::kSequence;
      for (const YAML::Node& item : node)
        out.children.push_back(ConvertYaml(item, file, depth + 1));
      break;
    case YAML::NodeType::Map:
      out.kind = StorageNode::Kind::kMap;
      for (auto it = node.begin(); it != node.end(); ++it) {
        if (!it->first.IsScalar()) {
          throw FileError(file, MarkLine(it->first.Mark()), "",
                          "expected a plain key, got a complex (map or sequence) key");
        }
        StorageNode child = ConvertYaml(it->second, file, depth + 1);
        child.key = it->first.Scalar();
        child.key_line = MarkLine(it->first.Mark());
        if (child.line == 0) child.line = child.key_line;
        out.children.push_back(std::move(child));
      }
      break;
    case YAML::NodeType::Null:
    case YAML::NodeType::Undefined:
      break;  // an empty scalar
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// OpenCV FileStorage XML: a small recursive-descent parser for the subset FileStorage writes.

class XmlParser {
 public:
  XmlParser(std::string_view text, const std::string& file) : text_(text), file_(file) {}

  StorageNode Parse() {
    if (text_.starts_with(kUtf8Bom)) pos_ = kUtf8Bom.size();
    SkipMisc();
    if (AtEnd()) Fail("empty file: expected <opencv_storage>");
    if (Peek() != '<') Fail("not an XML file: expected '<' at the start");
    StorageNode root = ParseElement(0);
    if (root.key != "opencv_storage") {
      throw FileError(file_, root.key_line, "opencv_storage",
                      "expected the root element <opencv_storage>, got <" + root.key + ">");
    }
    SkipMisc();
    if (!AtEnd()) Fail("unexpected content after </opencv_storage>");
    if (root.kind == StorageNode::Kind::kScalar) {
      if (!root.text.empty()) {
        throw FileError(file_, root.line, "opencv_storage",
                        "expected elements inside <opencv_storage>, got text");
      }
      root.kind = StorageNode::Kind::kMap;  // an empty storage
    }
    return root;
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const { throw FileError(file_, line_, "", what); }

  bool AtEnd() const { return pos_ >= text_.size(); }
  char Peek() const { return text_[pos_]; }
  bool StartsWith(std::string_view s) const { return text_.substr(pos_).starts_with(s); }
  void Advance(size_t n = 1) {
    for (size_t i = 0; i < n && pos_ < text_.size(); ++i, ++pos_) {
      if (text_[pos_] == '\n') ++line_;
    }
  }
  void SkipWhitespace() {
    while (!AtEnd() && IsSpace(Peek())) Advance();
  }
  // Advances past the next `terminator`; fails naming `what` at its start line if none.
  void SkipPast(std::string_view terminator, std::string_view what) {
    const int start_line = line_;
    const size_t end = text_.find(terminator, pos_);
    if (end == std::string_view::npos) {
      throw FileError(file_, start_line, "", "unterminated " + std::string(what));
    }
    Advance(end + terminator.size() - pos_);
  }
  // Whitespace, comments, processing instructions (<?xml ...?>) and a DOCTYPE.
  void SkipMisc() {
    while (true) {
      SkipWhitespace();
      if (StartsWith("<!--")) {
        SkipPast("-->", "comment <!--");
      } else if (StartsWith("<?")) {
        SkipPast("?>", "processing instruction <?");
      } else if (StartsWith("<!DOCTYPE")) {
        SkipPast(">", "<!DOCTYPE");
      } else {
        return;
      }
    }
  }

  static bool IsNameChar(char c, bool first) {
    const auto u = static_cast<unsigned char>(c);
    if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || c == ':' || u >= 0x80) {
      return true;
    }
    return !first && ((c >= '0' && c <= '9') || c == '-' || c == '.');
  }

  std::string ParseName() {
    const size_t start = pos_;
    while (!AtEnd() && IsNameChar(Peek(), pos_ == start)) Advance();
    return std::string(text_.substr(start, pos_ - start));
  }

  static void AppendUtf8(std::string* out, uint32_t code) {
    if (code < 0x80) {
      *out += static_cast<char>(code);
    } else if (code < 0x800) {
      *out += static_cast<char>(0xC0 | (code >> 6));
      *out += static_cast<char>(0x80 | (code & 0x3F));
    } else if (code < 0x10000) {
      *out += static_cast<char>(0xE0 | (code >> 12));
      *out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
      *out += static_cast<char>(0x80 | (code & 0x3F));
    } else {
      *out += static_cast<char>(0xF0 | (code >> 18));
      *out += static_cast<char>(0x80 | ((code >> 12) & 0x3F));
      *out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
      *out += static_cast<char>(0x80 | (code & 0x3F));
    }
  }

  // At '&': appends the decoded entity to *out.
  void ParseEntity(std::string* out) {
    const size_t end = text_.find(';', pos_);
    if (end == std::string_view::npos || end - pos_ > 12) Fail("unterminated entity: expected ';'");
    const std::string_view name = text_.substr(pos_ + 1, end - pos_ - 1);
    if (name == "lt") {
      *out += '<';
    } else if (name == "gt") {
      *out += '>';
    } else if (name == "amp") {
      *out += '&';
    } else if (name == "quot") {
      *out += '"';
    } else if (name == "apos") {
      *out += '\'';
    } else if (name.size() >= 2 && name[0] == '#') {
      const bool hex = name[1] == 'x' || name[1] == 'X';
      const std::string_view digits = name.substr(hex ? 2 : 1);
      uint32_t code = 0;
      bool ok = !digits.empty();
      for (char c : digits) {
        int digit = -1;
        if (c >= '0' && c <= '9') digit = c - '0';
        if (hex && c >= 'a' && c <= 'f') digit = c - 'a' + 10;
        if (hex && c >= 'A' && c <= 'F') digit = c - 'A' + 10;
        if (digit < 0) ok = false;
        code = code * (hex ? 16 : 10) + static_cast<uint32_t>(std::max(digit, 0));
        if (code > 0x10FFFF) ok = false;
      }
      if (!ok || code == 0) Fail("invalid character reference &" + std::string(name) + ";");
      AppendUtf8(out, code);
    } else {
      Fail("unknown entity &" + std::string(name) + "; (expected &lt; &gt; &amp; &quot; &apos;)");
    }
    Advance(end + 1 - pos_);
  }

  // At '<' of a start tag.
  StorageNode ParseElement(int depth) {
    StorageNode node;
    node.key_line = line_;
    if (depth > kMaxDepth) Fail("nesting too deep");
    Advance();  // '<'
    node.key = ParseName();
    if (node.key.empty()) Fail("expected an element name after '<'");
    if (!ParseAttributes(&node)) {
      node.line = line_;
      return node;  // an empty scalar
    }
    ParseContent(depth, &node);
    return node;
  }

  // After the element's name: its attributes (type_id into node->type_id) up to the end of
  // the start tag. False when the tag closes the element (`/>`), true when content follows.
  bool ParseAttributes(StorageNode* node) {
    while (true) {
      SkipWhitespace();
      if (AtEnd()) Fail("unexpected end of file in the tag <" + node->key + ">");
      if (StartsWith("/>")) {
        Advance(2);
        return false;
      }
      if (Peek() == '>') {
        Advance();
        return true;
      }
      const std::string attribute = ParseName();
      if (attribute.empty()) {
        Fail("unexpected '" + std::string(1, Peek()) + "' in the tag <" + node->key + ">");
      }
      SkipWhitespace();
      if (AtEnd() || Peek() != '=') Fail("expected '=' after the attribute " + attribute);
      Advance();
      SkipWhitespace();
      if (AtEnd() || (Peek() != '"' && Peek() != '\'')) {
        Fail("expected a quoted value for the attribute " + attribute);
      }
      const std::string value = ParseAttributeValue(attribute);
      if (attribute == "type_id") node->type_id = value;
    }
  }

  // At the opening quote of the attribute's value: the value, entities decoded.
  std::string ParseAttributeValue(const std::string& attribute) {
    const char quote = Peek();
    Advance();
    std::string value;
    while (true) {
      if (AtEnd()) Fail("unterminated value of the attribute " + attribute);
      const char c = Peek();
      if (c == quote) break;
      if (c == '<') Fail("'<' in the value of the attribute " + attribute);
      if (c == '&') {
        ParseEntity(&value);
      } else {
        value += c;
        Advance();
      }
    }
    Advance();  // closing quote
    return value;
  }

  // After the start tag: the element's content up to and with its end tag, as child elements
  // (a map, or a sequence when every child is <_>) or text (a scalar).
  void ParseContent(int depth, StorageNode* node) {
    const int content_line = line_;
    std::string text;
    int text_line = 0;  // line of the first non-whitespace character of the text
    bool has_children = false;
    bool all_items = true;  // every child is <_>: an OpenCV sequence
    while (true) {
      if (AtEnd()) {
        throw FileError(file_, line_, node->key,
                        "unexpected end of file: <" + node->key + "> opened at line " +
                            std::to_string(node->key_line) + " is not closed");
      }
      if (StartsWith("<!--")) {
        SkipPast("-->", "comment <!--");
      } else if (StartsWith("<![CDATA[")) {
        Advance(9);
        const size_t end = text_.find("]]>", pos_);
        if (end == std::string_view::npos) Fail("unterminated <![CDATA[");
        if (text_line == 0) text_line = line_;
        text += text_.substr(pos_, end - pos_);
        Advance(end + 3 - pos_);
      } else if (StartsWith("<?")) {
        SkipPast("?>", "processing instruction <?");
      } else if (StartsWith("</")) {
        ParseEndTag(*node);
        break;
      } else if (Peek() == '<') {
        StorageNode child = ParseElement(depth + 1);
        if (child.key != "_") all_items = false;
        node->children.push_back(std::move(child));
        has_children = true;
      } else {
        const char c = Peek();
        if (text_line == 0 && !IsSpace(c)) text_line = line_;
        if (c == '&') {
          ParseEntity(&text);
        } else {
          text += c;
          Advance();
        }
      }
    }
    const auto first = std::find_if_not(text.begin(), text.end(), IsSpace);
    if (has_children) {
      if (first != text.end()) {
        throw FileError(file_, text_line, node->key,
                        "unexpected text mixed with elements inside <" + node->key + ">");
      }
      node->kind = all_items ? StorageNode::Kind::kSequence : StorageNode::Kind::kMap;
      node->line = node->children.front().key_line;
      return;
    }
    // A scalar: drop surrounding whitespace and the quotes FileStorage writes around strings.
    const auto last = std::find_if_not(text.rbegin(), text.rend(), IsSpace).base();
    node->text = first < last ? std::string(first, last) : std::string();
    if (node->text.size() >= 2 && node->text.front() == '"' && node->text.back() == '"') {
      node->text = node->text.substr(1, node->text.size() - 2);
    }
    node->line = text_line != 0 ? text_line : content_line;
  }

  // At "</": the end tag, which must close `node`.
  void ParseEndTag(const StorageNode& node) {
    const int close_line = line_;
    Advance(2);
    const std::string name = ParseName();
    SkipWhitespace();
    if (AtEnd() || Peek() != '>') Fail("expected '>' to end </" + name);
    Advance();
    if (name != node.key) {
      throw FileError(file_, close_line, node.key,
                      "expected </" + node.key + "> to close <" + node.key + "> opened at line " +
                          std::to_string(node.key_line) + ", got </" + name + ">");
    }
  }

  std::string_view text_;
  const std::string& file_;
  size_t pos_ = 0;
  int line_ = 1;
};

}  // namespace

const StorageNode* StorageNode::Find(std::string_view child_key, const std::string& file) const {
  const StorageNode* found = nullptr;
  for (const StorageNode& child : children) {
    if (child.key != child_key) continue;
    if (found != nullptr) {
      throw FileError(file, child.key_line, std::string(child_key),
                      "duplicate key (first at line " + std::to_string(found->key_line) + ")");
    }
    found = &child;
  }
  return found;
}

std::vector<StorageToken> Tokens(const StorageNode& node, const std::string& file,
                                 const std::string& key) {
  std::vector<StorageToken> tokens;
  if (node.kind == StorageNode::Kind::kSequence) {
    for (const StorageNode& item : node.children) {
      if (item.kind != StorageNode::Kind::kScalar) {
        throw FileError(file, item.line, key,
                        "expected a number, got " + std::string(KindName(item.kind)));
      }
      tokens.push_back({item.text, item.line});
    }
    return tokens;
  }
  if (node.kind == StorageNode::Kind::kMap) {
    throw FileError(file, node.line, key, "expected a list of numbers, got a map");
  }
  const std::string_view text = node.text;
  int line = node.line;
  size_t i = 0;
  while (i < text.size()) {
    if (IsSpace(text[i])) {
      if (text[i] == '\n' && line > 0) ++line;
      ++i;
      continue;
    }
    const size_t start = i;
    while (i < text.size() && !IsSpace(text[i])) ++i;
    tokens.push_back({text.substr(start, i - start), line});
  }
  return tokens;
}

StorageNode ParseYamlStorage(const std::string& text, const std::string& file) {
  std::string yaml = text;
  if (std::string_view(yaml).starts_with(kUtf8Bom)) yaml.erase(0, kUtf8Bom.size());
  // FileStorage writes "%YAML:1.0", which is not a valid YAML directive: blank that line
  // (keeping the newline, so line numbers stay right).
  if (yaml.starts_with("%YAML")) {
    const size_t end = std::min(yaml.find('\n'), yaml.size());
    std::fill(yaml.begin(), yaml.begin() + static_cast<std::ptrdiff_t>(end), ' ');
  }
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw FileError(file, MarkLine(e.mark), "", "not valid YAML: " + e.msg);
  }
  if (root.IsNull()) throw FileError(file, 0, "", "empty file: expected YAML keys");
  if (!root.IsMap()) {
    throw FileError(file, MarkLine(root.Mark()), "",
                    "expected YAML keys (a map) at the top level, got " +
                        std::string(root.IsSequence() ? "a sequence" : "a scalar"));
  }
  try {
    return ConvertYaml(root, file, 0);
  } catch (const YAML::Exception& e) {
    throw FileError(file, MarkLine(e.mark), "", "not valid YAML: " + e.msg);
  }
}

StorageNode ParseXmlStorage(const std::string& text, const std::string& file) {
  return XmlParser(text, file).Parse();
}

std::string FormatDouble(double value) {
  // %.17g, but independent of the C locale (no decimal comma).
  char buffer[64];
  const auto result =
      std::to_chars(buffer, buffer + sizeof(buffer), value, std::chars_format::general, 17);
  std::string s(buffer, result.ptr);
  if (!std::isfinite(value) || s.find('.') != std::string::npos) return s;
  const size_t e = s.find('e');
  s.insert(e == std::string::npos ? s.size() : e, ".0");
  return s;
}

std::string YamlQuoted(std::string_view value) {
  std::string out = "\"";
  for (char c : value) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

namespace {
std::string XmlQuoted(std::string_view value) {
  std::string out = "\"";
  for (char c : value) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out + "\"";
}
}  // namespace

OpenCvStorageWriter::OpenCvStorageWriter(bool xml) : xml_(xml) {
  out_ = xml_ ? "<?xml version=\"1.0\"?>\n<opencv_storage>\n" : "%YAML:1.0\n---\n";
}

void OpenCvStorageWriter::WriteInt(std::string_view key, long long value) {
  const std::string k(key);
  const std::string v = std::to_string(value);
  out_ += xml_ ? "<" + k + ">" + v + "</" + k + ">\n" : k + ": " + v + "\n";
}

void OpenCvStorageWriter::WriteString(std::string_view key, std::string_view value) {
  const std::string k(key);
  out_ += xml_ ? "<" + k + ">" + XmlQuoted(value) + "</" + k + ">\n"
               : k + ": " + YamlQuoted(value) + "\n";
}

void OpenCvStorageWriter::WriteMatrix(std::string_view key, int rows, int cols,
                                      std::span<const double> data) {
  const std::string k(key);
  const std::string r = std::to_string(rows);
  const std::string c = std::to_string(cols);
  // One matrix row per line, as a person would lay it out.
  std::string values;
  for (size_t i = 0; i < data.size(); ++i) {
    const bool row_end = cols > 0 && (i + 1) % static_cast<size_t>(cols) == 0;
    values += FormatDouble(data[i]);
    if (i + 1 == data.size()) break;
    if (xml_) {
      values += row_end ? "\n    " : " ";
    } else {
      values += row_end ? ",\n       " : ", ";
    }
  }
  if (xml_) {
    out_ += "<" + k + " type_id=\"opencv-matrix\">\n  <rows>" + r + "</rows>\n  <cols>" + c +
            "</cols>\n  <dt>d</dt>\n  <data>\n    " + values + "</data></" + k + ">\n";
  } else {
    out_ += k + ": !!opencv-matrix\n   rows: " + r + "\n   cols: " + c + "\n   dt: d\n   data: [ " +
            values + (data.empty() ? "]\n" : " ]\n");
  }
}

std::string OpenCvStorageWriter::Finish() {
  if (xml_) out_ += "</opencv_storage>\n";
  return std::move(out_);
}

}  // namespace saccade::geometry::internal
