#include <fmt/format.h>
#include <zstd.h>

#include <cstdio>
#include <cstring>
#include <fstream>

#include "record/internal_mcap_bytes.h"
#include "saccade/core/error.h"
#include "saccade/record/mcap.h"

namespace saccade::record {

using internal::Crc32;
using internal::Reader;

namespace reader_detail {

constexpr uint64_t kMaxChunkBytes = uint64_t{512} << 20;

// The reader keeps no file open: each pass opens it again (a reader may outlive many passes).
class File {
 public:
  explicit File(const std::filesystem::path& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) throw FileError(path.string(), 0, "", "cannot open the recording");
    in_.seekg(0, std::ios::end);
    size_ = static_cast<uint64_t>(in_.tellg());
    in_.seekg(0);
  }
  uint64_t size() const { return size_; }
  /// `n` bytes at `at`; false when the file ends before.
  bool Read(uint64_t at, uint64_t n, std::vector<uint8_t>* out) {
    if (at > size_ || n > size_ - at) return false;
    out->resize(n);
    in_.seekg(static_cast<std::streamoff>(at));
    in_.read(reinterpret_cast<char*>(out->data()), static_cast<std::streamsize>(n));
    return static_cast<uint64_t>(in_.gcount()) == n;
  }

 private:
  std::filesystem::path path_;
  std::ifstream in_;
  uint64_t size_ = 0;
};

}  // namespace reader_detail

using namespace reader_detail;  // NOLINT: this file's own helpers

struct McapReader::Impl {
  std::filesystem::path path;
  std::string profile, library;
  std::map<uint16_t, McapSchema> schemas;
  std::map<uint16_t, McapChannel> channels;
  McapStatistics stats;
  std::vector<McapMetadata> metadata;
  bool recovered = false;
  uint64_t lost_bytes = 0;
  uint64_t data_start = 0;  // the first record after the header

  [[noreturn]] void Fail(uint64_t at, const std::string& what) const {
    throw FileError(path.string(), 0, "", fmt::format("byte {}: {}", at, what));
  }
  void ReadSchema(Reader r, uint64_t at) {
    McapSchema s;
    s.id = r.U16();
    s.name = r.String();
    s.encoding = r.String();
    s.data = r.String();
    if (!r.ok()) Fail(at, "a Schema record shorter than its fields");
    if (s.id != 0) schemas[s.id] = std::move(s);
  }
  void ReadChannel(Reader r, uint64_t at) {
    McapChannel c;
    c.id = r.U16();
    c.schema_id = r.U16();
    c.topic = r.String();
    c.message_encoding = r.String();
    c.metadata = r.StringMap();
    if (!r.ok()) Fail(at, "a Channel record shorter than its fields");
    channels[c.id] = std::move(c);
  }
  void ReadMetadata(Reader r, uint64_t at) {
    McapMetadata m;
    m.name = r.String();
    m.values = r.StringMap();
    if (!r.ok()) Fail(at, "a Metadata record shorter than its fields");
    metadata.push_back(std::move(m));
  }
  void ReadStatistics(Reader r, uint64_t at) {
    stats.message_count = r.U64();
    r.U16();  // schemas
    r.U32();  // channels
    r.U32();  // attachments
    r.U32();  // metadata
    stats.chunk_count = r.U32();
    stats.message_start_time = r.U64();
    stats.message_end_time = r.U64();
    Reader counts(r.Take(r.U32()));
    while (counts.ok() && counts.left() > 0) {
      const uint16_t channel = counts.U16();
      stats.channel_message_counts[channel] = counts.U64();
    }
    if (!r.ok() || !counts.ok()) Fail(at, "a Statistics record shorter than its fields");
  }
  /// The records of a chunk's content, decompressed into `*records`.
  void Decompress(Reader chunk, uint64_t at, std::vector<uint8_t>* records) const;
  /// Walks the data section; `visit` gets each record (opcode, content, its offset in the file
  /// or, inside a chunk, in the chunk's records). Stops at Data End, at the end of the file, or
  /// when a record runs past it (cut short: returns that record's offset), or when visit says.
  uint64_t Walk(File& file,
                const std::function<bool(uint8_t, std::span<const uint8_t>, uint64_t)>& visit,
                bool into_chunks) const;
  void Scan(File& file);
  bool ReadSummary(File& file);
};

void McapReader::Impl::Decompress(Reader chunk, uint64_t at, std::vector<uint8_t>* out) const {
  chunk.U64();  // start
  chunk.U64();  // end
  const uint64_t size = chunk.U64();
  const uint32_t crc = chunk.U32();
  const std::string compression = chunk.String();
  const std::span<const uint8_t> records = chunk.Take(chunk.U64());
  if (!chunk.ok()) Fail(at, "a Chunk record shorter than its fields");
  if (compression.empty()) {
    if (records.size() != size) Fail(at, "a chunk's size is not its records'");
    out->assign(records.begin(), records.end());
  } else if (compression == "zstd") {
    // Chunks hold a few MiB (writers close them at 1-4 MiB; one message may add an image);
    // a larger size is damage, not a chunk, and is not allocated.
    if (size > kMaxChunkBytes) {
      Fail(at, fmt::format("a chunk of {} bytes (more than {} MiB)", size, kMaxChunkBytes >> 20));
    }
    const unsigned long long declared = ZSTD_getFrameContentSize(records.data(), records.size());
    if (declared != ZSTD_CONTENTSIZE_UNKNOWN && declared != size) {
      Fail(at, fmt::format("a zstd chunk whose frame holds {} bytes, not its {}", declared, size));
    }
    out->resize(size);
    const std::size_t n = ZSTD_decompress(out->data(), size, records.data(), records.size());
    if (ZSTD_isError(n) || n != size) {
      Fail(at, fmt::format("a zstd chunk that does not decompress to its {} bytes{}", size,
                           ZSTD_isError(n) ? std::string(": ") + ZSTD_getErrorName(n) : ""));
    }
  } else {
    Fail(at, fmt::format("a chunk compressed with '{}': saccade reads zstd and none", compression));
  }
  if (crc != 0 && Crc32(*out) != crc) Fail(at, "a chunk whose CRC32 does not match its records");
}

uint64_t McapReader::Impl::Walk(
    File& file, const std::function<bool(uint8_t, std::span<const uint8_t>, uint64_t)>& visit,
    bool into_chunks) const {
  std::vector<uint8_t> prefix, content, records;
  uint64_t at = data_start;
  while (at < file.size()) {
    if (!file.Read(at, internal::kRecordPrefix, &prefix)) return at;
    Reader p(prefix);
    const uint8_t opcode = p.U8();
    const uint64_t length = p.U64();
    if (opcode == internal::kDataEnd || opcode == internal::kFooter) return 0;
    if (!file.Read(at + internal::kRecordPrefix, length, &content)) return at;
    if (opcode == internal::kChunk && into_chunks) {
      Decompress(Reader(content), at, &records);
      Reader inner(records);
      while (inner.left() > 0) {
        const uint64_t inner_at = inner.pos();
        const uint8_t inner_op = inner.U8();
        const std::span<const uint8_t> inner_content = inner.Take(inner.U64());
        if (!inner.ok()) Fail(at, fmt::format("a chunk whose record at {} runs past it", inner_at));
        if (!visit(inner_op, inner_content, inner_at)) return 0;
      }
    } else if (!visit(opcode, content, at)) {
      return 0;
    }
    at += internal::kRecordPrefix + length;
  }
  return at == file.size() ? 0 : at;
}

void McapReader::Impl::Scan(File& file) {
  stats = {};
  metadata.clear();
  const uint64_t cut = Walk(
      file,
      [&](uint8_t opcode, std::span<const uint8_t> content, uint64_t at) {
        if (opcode == internal::kSchema) ReadSchema(Reader(content), at);
        if (opcode == internal::kChannel) ReadChannel(Reader(content), at);
        if (opcode == internal::kMessage) {
          Reader r(content);
          const uint16_t channel = r.U16();
          r.U32();
          const uint64_t time = r.U64();
          if (!r.ok()) Fail(at, "a Message record shorter than its fields");
          stats.message_start_time =
              stats.message_count == 0 ? time : std::min(stats.message_start_time, time);
          stats.message_end_time = std::max(stats.message_end_time, time);
          ++stats.message_count;
          ++stats.channel_message_counts[channel];
        }
        if (opcode == internal::kChunk) ++stats.chunk_count;
        if (opcode == internal::kMetadata) ReadMetadata(Reader(content), at);
        return true;
      },
      true);
  lost_bytes = cut == 0 ? 0 : file.size() - cut;
}

bool McapReader::Impl::ReadSummary(File& file) {
  const uint64_t size = file.size();
  if (size < 8 + internal::kFooterRecord + 8) return false;
  std::vector<uint8_t> tail;
  if (!file.Read(size - internal::kFooterRecord - 8, internal::kFooterRecord + 8, &tail)) {
    return false;
  }
  if (std::memcmp(tail.data() + internal::kFooterRecord, internal::kMagic, 8) != 0) return false;
  Reader footer(tail);
  if (footer.U8() != internal::kFooter || footer.U64() != 20) return false;
  const uint64_t summary_start = footer.U64();
  const uint64_t summary_offset_start = footer.U64();
  const uint32_t summary_crc = footer.U32();
  const uint64_t footer_at = size - internal::kFooterRecord - 8;
  if (summary_start == 0) return true;  // complete, but without a summary: scan
  if (summary_start > footer_at) Fail(footer_at, "a footer whose summary starts past it");
  std::vector<uint8_t> summary;
  file.Read(summary_start, footer_at - summary_start, &summary);
  if (summary_crc != 0 && Crc32(std::span<const uint8_t>(tail).first(internal::kRecordPrefix + 16),
                                Crc32(summary)) != summary_crc) {
    Fail(summary_start, "a summary whose CRC32 does not match");
  }
  const uint64_t end =
      summary_offset_start != 0 ? summary_offset_start - summary_start : summary.size();
  Reader r(std::span<const uint8_t>(summary).first(std::min<uint64_t>(end, summary.size())));
  bool statistics = false;
  std::vector<std::pair<uint64_t, uint64_t>> metadata_records;  // offset, length
  while (r.left() > 0) {
    const uint64_t at = summary_start + r.pos();
    const uint8_t opcode = r.U8();
    const std::span<const uint8_t> content = r.Take(r.U64());
    if (!r.ok()) Fail(at, "a summary record that runs past the summary");
    if (opcode == internal::kSchema) ReadSchema(Reader(content), at);
    if (opcode == internal::kChannel) ReadChannel(Reader(content), at);
    if (opcode == internal::kStatistics) {
      ReadStatistics(Reader(content), at);
      statistics = true;
    }
    if (opcode == internal::kMetadataIndex) {
      Reader index(content);
      const uint64_t offset = index.U64();
      const uint64_t length = index.U64();
      if (!index.ok()) Fail(at, "a Metadata Index record shorter than its fields");
      metadata_records.emplace_back(offset, length);
    }
  }
  std::vector<uint8_t> record;
  for (const auto& [offset, length] : metadata_records) {
    if (length < internal::kRecordPrefix || !file.Read(offset, length, &record) ||
        record[0] != internal::kMetadata) {
      Fail(offset, "a Metadata Index that points at no Metadata record");
    }
    ReadMetadata(Reader(std::span<const uint8_t>(record).subspan(internal::kRecordPrefix)), offset);
  }
  return statistics;
}

McapReader::McapReader(const std::filesystem::path& path) : impl_(std::make_shared<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw FileError(path.string(), 0, "", "no such recording (an .mcap file)");
  }
  File file(path);
  std::vector<uint8_t> start;
  if (!file.Read(0, 8 + internal::kRecordPrefix, &start) ||
      std::memcmp(start.data(), internal::kMagic, 8) != 0) {
    throw FileError(path.string(), 0, "",
                    "not an MCAP file: it does not begin with MCAP's magic bytes (0x89 MCAP0)");
  }
  Reader prefix(std::span<const uint8_t>(start).subspan(8));
  const uint8_t opcode = prefix.U8();
  const uint64_t length = prefix.U64();
  std::vector<uint8_t> header;
  if (opcode != internal::kHeader || !file.Read(8 + internal::kRecordPrefix, length, &header)) {
    m.Fail(8, "no Header record after the magic bytes");
  }
  Reader h(header);
  m.profile = h.String();
  m.library = h.String();
  if (!h.ok()) m.Fail(8, "a Header record shorter than its fields");
  m.data_start = 8 + internal::kRecordPrefix + length;
  const bool complete = m.ReadSummary(file);
  if (!complete) {
    // No footer (cut short) or no statistics in the summary: count what the data holds.
    std::vector<uint8_t> tail;
    const bool has_footer = file.size() >= 16 && file.Read(file.size() - 8, 8, &tail) &&
                            std::memcmp(tail.data(), internal::kMagic, 8) == 0;
    m.recovered = !has_footer;
    m.Scan(file);
  }
}

McapReader::~McapReader() = default;

const std::string& McapReader::profile() const { return impl_->profile; }
const std::string& McapReader::library() const { return impl_->library; }
const std::map<uint16_t, McapSchema>& McapReader::schemas() const { return impl_->schemas; }
const std::map<uint16_t, McapChannel>& McapReader::channels() const { return impl_->channels; }
const std::vector<McapMetadata>& McapReader::metadata() const { return impl_->metadata; }
const McapStatistics& McapReader::statistics() const { return impl_->stats; }
bool McapReader::recovered() const { return impl_->recovered; }
uint64_t McapReader::lost_bytes() const { return impl_->lost_bytes; }

// Reads top-level records from the first after the header; a chunk's records in turn.
class McapReader::MessageCursor final : public McapReader::Cursor {
 public:
  explicit MessageCursor(std::shared_ptr<const McapReader::Impl> impl)
      : impl_(std::move(impl)), file_(impl_->path), at_(impl_->data_start) {}

  bool Next(McapMessage* m) override;

 private:
  std::shared_ptr<const McapReader::Impl> impl_;
  File file_;
  uint64_t at_;            // the next top-level record
  uint64_t chunk_at_ = 0;  // the chunk being read (for errors)
  std::vector<uint8_t> prefix_, content_, records_;
  std::size_t inner_ = 0;  // the next record in records_
  bool in_chunk_ = false, done_ = false;
};

bool McapReader::MessageCursor::Next(McapMessage* m) {
  const auto message = [&](std::span<const uint8_t> content, uint64_t at) {
    Reader r(content);
    m->channel_id = r.U16();
    m->sequence = r.U32();
    m->log_time = r.U64();
    m->publish_time = r.U64();
    m->data = r.Take(r.left());
    if (!r.ok()) impl_->Fail(at, "a Message record shorter than its fields");
  };
  while (!done_) {
    if (in_chunk_) {
      Reader inner(std::span<const uint8_t>(records_).subspan(inner_));
      if (inner.left() == 0) {
        in_chunk_ = false;
        continue;
      }
      const uint8_t opcode = inner.U8();
      const std::span<const uint8_t> content = inner.Take(inner.U64());
      if (!inner.ok()) {
        impl_->Fail(chunk_at_, fmt::format("a chunk whose record at {} runs past it", inner_));
      }
      inner_ += inner.pos();
      if (opcode != internal::kMessage) continue;
      message(content, chunk_at_);
      return true;
    }
    if (at_ >= file_.size() || !file_.Read(at_, internal::kRecordPrefix, &prefix_)) break;
    Reader p(prefix_);
    const uint8_t opcode = p.U8();
    const uint64_t length = p.U64();
    if (opcode == internal::kDataEnd || opcode == internal::kFooter) break;
    if (!file_.Read(at_ + internal::kRecordPrefix, length, &content_)) break;  // cut short
    const uint64_t at = at_;
    at_ += internal::kRecordPrefix + length;
    if (opcode == internal::kChunk) {
      impl_->Decompress(Reader(content_), at, &records_);
      chunk_at_ = at;
      inner_ = 0;
      in_chunk_ = true;
    } else if (opcode == internal::kMessage) {
      message(content_, at);
      return true;
    }
  }
  done_ = true;
  return false;
}

std::unique_ptr<McapReader::Cursor> McapReader::Messages() const {
  return std::make_unique<MessageCursor>(impl_);
}

void McapReader::ForEachMessage(const std::function<bool(const McapMessage&)>& visit) const {
  const auto cursor = Messages();
  McapMessage m;
  while (cursor->Next(&m)) {
    if (!visit(m)) return;
  }
}

}  // namespace saccade::record
