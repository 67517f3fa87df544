#pragma once
// MCAP's serialization (spec: "Serialization"): little-endian integers, uint32-prefixed strings
// and maps, records as <opcode uint8><length uint64><content>; and its CRC32 (the IEEE 802.3
// polynomial, reflected: zlib's crc32).
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace saccade::record::internal {

inline constexpr uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

enum Opcode : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

/// A record's opcode and length prefix: 9 bytes.
inline constexpr uint64_t kRecordPrefix = 9;
/// The footer record (prefix, summary_start, summary_offset_start, summary_crc) and the magic.
inline constexpr uint64_t kFooterRecord = kRecordPrefix + 8 + 8 + 4;

/// CRC32 (IEEE), continued from `crc` (0 to start): zlib's crc32, several times faster than a
/// byte-wise table (the writer checksums every chunk and the whole data section).
inline uint32_t Crc32(std::span<const uint8_t> bytes, uint32_t crc = 0) {
  constexpr std::size_t kMost = std::size_t{1} << 30;  // crc32's length is an unsigned int
  for (std::size_t at = 0; at < bytes.size(); at += kMost) {
    const std::size_t n = std::min(kMost, bytes.size() - at);
    crc = static_cast<uint32_t>(::crc32(crc, bytes.data() + at, static_cast<uInt>(n)));
  }
  return crc;
}

/// Bytes being serialized.
class Bytes {
 public:
  void U8(uint8_t v) { data_.push_back(v); }
  void U16(uint16_t v) { Little(v, 2); }
  void U32(uint32_t v) { Little(v, 4); }
  void U64(uint64_t v) { Little(v, 8); }
  void Raw(std::span<const uint8_t> bytes) {
    data_.insert(data_.end(), bytes.begin(), bytes.end());
  }
  void String(const std::string& s) {
    U32(static_cast<uint32_t>(s.size()));
    Raw({reinterpret_cast<const uint8_t*>(s.data()), s.size()});
  }
  void StringMap(const std::map<std::string, std::string>& map) {
    Bytes entries;
    for (const auto& [key, value] : map) {
      entries.String(key);
      entries.String(value);
    }
    U32(static_cast<uint32_t>(entries.size()));
    Raw(entries.data());
  }
  /// A whole record: opcode, length, content.
  void Record(uint8_t opcode, const Bytes& content) {
    U8(opcode);
    U64(content.size());
    Raw(content.data());
  }
  void Clear() { data_.clear(); }
  std::size_t size() const { return data_.size(); }
  std::span<const uint8_t> data() const { return data_; }
  std::vector<uint8_t>& vector() { return data_; }

 private:
  void Little(uint64_t v, int n) {
    for (int i = 0; i < n; ++i) data_.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  std::vector<uint8_t> data_;
};

/// Reads serialized fields from a span; every read checks the bounds. `ok()` turns false on
/// the first read past the end, and every later read gives zeros.
class Reader {
 public:
  explicit Reader(std::span<const uint8_t> data) : data_(data) {}
  uint8_t U8() { return static_cast<uint8_t>(Little(1)); }
  uint16_t U16() { return static_cast<uint16_t>(Little(2)); }
  uint32_t U32() { return static_cast<uint32_t>(Little(4)); }
  uint64_t U64() { return Little(8); }
  std::span<const uint8_t> Take(uint64_t n) {
    if (!ok_ || n > data_.size() - pos_) {
      ok_ = false;
      return {};
    }
    const std::span<const uint8_t> out = data_.subspan(pos_, n);
    pos_ += n;
    return out;
  }
  std::string String() {
    const std::span<const uint8_t> bytes = Take(U32());
    return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
  }
  std::map<std::string, std::string> StringMap() {
    Reader entries(Take(U32()));
    std::map<std::string, std::string> map;
    while (ok_ && entries.ok() && entries.left() > 0) {
      std::string key = entries.String();
      map[key] = entries.String();
    }
    ok_ = ok_ && entries.ok();
    return map;
  }
  bool ok() const { return ok_; }
  uint64_t left() const { return data_.size() - pos_; }
  uint64_t pos() const { return pos_; }

 private:
  uint64_t Little(int n) {
    const std::span<const uint8_t> bytes = Take(n);
    uint64_t v = 0;
    for (std::size_t i = 0; i < bytes.size(); ++i) v |= uint64_t{bytes[i]} << (8 * i);
    return v;
  }
  std::span<const uint8_t> data_;
  uint64_t pos_ = 0;
  bool ok_ = true;
};

}  // namespace saccade::record::internal
