#include <fmt/format.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "record/internal_mcap_bytes.h"
#include "saccade/core/error.h"
#include "saccade/record/mcap.h"

namespace saccade::record {

using internal::Bytes;
using internal::Crc32;

namespace writer_detail {

// A Chunk Index record's fields, kept until the summary.
struct ChunkIndex {
  uint64_t start_time = 0, end_time = 0;
  uint64_t offset = 0, length = 0;
  std::map<uint16_t, uint64_t> message_index_offsets;
  uint64_t message_index_length = 0;
  std::string compression;
  uint64_t compressed_size = 0, uncompressed_size = 0;
};

// The contents of Schema and Channel records: the same in a chunk and in the summary.
Bytes SchemaContent(const McapSchema& s) {
  Bytes c;
  c.U16(s.id);
  c.String(s.name);
  c.String(s.encoding);
  c.String(s.data);  // uint32-prefixed bytes: as a string
  return c;
}

Bytes ChannelContent(const McapChannel& ch) {
  Bytes c;
  c.U16(ch.id);
  c.U16(ch.schema_id);
  c.String(ch.topic);
  c.String(ch.message_encoding);
  c.StringMap(ch.metadata);
  return c;
}

}  // namespace writer_detail

using namespace writer_detail;  // NOLINT: this file's own helpers

struct McapWriter::Impl {
  std::filesystem::path path;
  McapWriterOptions options;
  std::FILE* file = nullptr;
  uint64_t offset = 0;    // bytes written
  uint32_t data_crc = 0;  // of every byte written before Data End
  std::map<uint16_t, McapSchema> schemas;
  std::map<uint16_t, McapChannel> channels;
  std::map<uint16_t, uint32_t> sequences;
  McapStatistics stats;
  std::vector<ChunkIndex> chunk_indexes;
  struct MetadataIndex {
    uint64_t offset = 0, length = 0;
    std::string name;
  };
  std::vector<MetadataIndex> metadata_indexes;
  // The open chunk: its records, their messages' offsets by channel, its time span.
  Bytes chunk;
  std::map<uint16_t, std::vector<std::pair<uint64_t, uint64_t>>> chunk_messages;
  uint64_t chunk_start = 0, chunk_end = 0;
  bool chunk_has_messages = false;
  std::vector<uint8_t> compressed;
  Bytes head, indexes;  // a chunk's record fields and its message indexes
  // zstd's context, kept from chunk to chunk (a fresh one is megabytes of fresh pages).
  struct FreeZstd {
    void operator()(ZSTD_CCtx* c) const { ZSTD_freeCCtx(c); }
  };
  std::unique_ptr<ZSTD_CCtx, FreeZstd> zstd;
  bool closed = false;

  void Put(std::span<const uint8_t> bytes, bool data_section = true) {
    Write(bytes);
    if (data_section) data_crc = Crc32(bytes, data_crc);
  }
  /// Bytes of the data section whose CRC32 is known: the section's CRC follows without a pass.
  void Put(std::span<const uint8_t> bytes, uint32_t crc) {
    Write(bytes);
    data_crc =
        static_cast<uint32_t>(crc32_combine(data_crc, crc, static_cast<z_off_t>(bytes.size())));
  }
  void Write(std::span<const uint8_t> bytes) {
    if (bytes.empty()) return;
    if (std::fwrite(bytes.data(), 1, bytes.size(), file) != bytes.size()) {
      throw FileError(path.string(), 0, "", fmt::format("cannot write: {}", std::strerror(errno)));
    }
    offset += bytes.size();
  }
  void FlushChunk();
  void WriteSummary();
};

McapWriter::McapWriter(const std::filesystem::path& path, McapWriterOptions options)
    : impl_(std::make_unique<Impl>()) {
  if (options.compression != "zstd" && !options.compression.empty()) {
    throw InvalidArgument(fmt::format("mcap: compression must be zstd or \"\" (none), got '{}'",
                                      options.compression));
  }
  if (options.zstd_level < -7 || options.zstd_level > 19 || options.zstd_level == 0) {
    throw InvalidArgument(
        fmt::format("mcap: zstd level must be -7..-1 (fast) or 1..19, got {}", options.zstd_level));
  }
  if (options.chunk_bytes < 1 || !(options.chunk_seconds > 0.0)) {
    throw InvalidArgument("mcap: chunk_bytes and chunk_seconds must be > 0");
  }
  impl_->path = path;
  impl_->options = std::move(options);
  impl_->file = std::fopen(path.c_str(), "wb");
  if (impl_->file == nullptr) {
    throw FileError(path.string(), 0, "",
                    fmt::format("cannot create the recording: {}", std::strerror(errno)));
  }
  impl_->Put(internal::kMagic);
  Bytes header, record;
  header.String(impl_->options.profile);
  header.String(impl_->options.library);
  record.Record(internal::kHeader, header);
  impl_->Put(record.data());
  std::fflush(impl_->file);
}

McapWriter::~McapWriter() {
  if (impl_->file != nullptr) {
    // Not closed: leave the file as a recording cut short (its complete chunks recoverable).
    try {
      impl_->FlushChunk();
    } catch (const std::exception&) {
    }
    std::fclose(impl_->file);
  }
}

uint16_t McapWriter::AddSchema(const std::string& name, const std::string& encoding,
                               const std::string& data) {
  if (impl_->schemas.size() >= 65535) throw InvalidArgument("mcap: more than 65,535 schemas");
  const auto id = static_cast<uint16_t>(impl_->schemas.size() + 1);
  impl_->schemas[id] = McapSchema{id, name, encoding, data};
  impl_->chunk.Record(internal::kSchema, SchemaContent(impl_->schemas[id]));
  return id;
}

uint16_t McapWriter::AddChannel(uint16_t schema_id, const std::string& topic,
                                const std::string& message_encoding,
                                const std::map<std::string, std::string>& metadata) {
  if (schema_id != 0 && !impl_->schemas.contains(schema_id)) {
    throw InvalidArgument(fmt::format("mcap: channel {}: unknown schema id {}", topic, schema_id));
  }
  if (impl_->channels.size() >= 65535) throw InvalidArgument("mcap: more than 65,535 channels");
  const auto id = static_cast<uint16_t>(impl_->channels.size() + 1);
  impl_->channels[id] = McapChannel{id, schema_id, topic, message_encoding, metadata};
  impl_->chunk.Record(internal::kChannel, ChannelContent(impl_->channels[id]));
  return id;
}

void McapWriter::AddMetadata(const std::string& name,
                             const std::map<std::string, std::string>& values) {
  Impl& w = *impl_;
  if (w.closed) throw InvalidArgument("mcap: metadata after Close");
  w.FlushChunk();  // records outside chunks go between them
  Bytes content, record;
  content.String(name);
  content.StringMap(values);
  record.Record(internal::kMetadata, content);
  w.metadata_indexes.push_back({w.offset, record.size(), name});
  w.Put(record.data());
  std::fflush(w.file);
}

void McapWriter::Write(uint16_t channel_id, uint64_t log_time, uint64_t publish_time,
                       std::span<const uint8_t> data) {
  Impl& w = *impl_;
  if (w.closed) throw InvalidArgument("mcap: write after Close");
  if (!w.channels.contains(channel_id)) {
    throw InvalidArgument(fmt::format("mcap: unknown channel id {}", channel_id));
  }
  // The chunk spans at most chunk_seconds of log time: a message beyond closes it first.
  const auto span_ns = static_cast<uint64_t>(w.options.chunk_seconds * 1e9);
  if (w.chunk_has_messages && log_time > w.chunk_start && log_time - w.chunk_start >= span_ns) {
    w.FlushChunk();
  }
  const uint32_t sequence = w.sequences[channel_id]++;
  w.chunk_messages[channel_id].emplace_back(log_time, w.chunk.size());
  w.chunk.U8(internal::kMessage);
  w.chunk.U64(2 + 4 + 8 + 8 + data.size());
  w.chunk.U16(channel_id);
  w.chunk.U32(sequence);
  w.chunk.U64(log_time);
  w.chunk.U64(publish_time);
  w.chunk.Raw(data);
  if (!w.chunk_has_messages) {
    w.chunk_start = w.chunk_end = log_time;
    w.chunk_has_messages = true;
  }
  w.chunk_start = std::min(w.chunk_start, log_time);
  w.chunk_end = std::max(w.chunk_end, log_time);
  McapStatistics& s = w.stats;
  s.message_start_time = s.message_count == 0 ? log_time : std::min(s.message_start_time, log_time);
  s.message_end_time = std::max(s.message_end_time, log_time);
  ++s.message_count;
  ++s.channel_message_counts[channel_id];
  if (w.chunk.size() >= w.options.chunk_bytes) w.FlushChunk();
}

void McapWriter::Impl::FlushChunk() {
  if (chunk.size() == 0) return;
  std::span<const uint8_t> records = chunk.data();
  if (options.compression == "zstd") {
    compressed.resize(ZSTD_compressBound(chunk.size()));
    if (zstd == nullptr) zstd.reset(ZSTD_createCCtx());
    const std::size_t n = ZSTD_compressCCtx(zstd.get(), compressed.data(), compressed.size(),
                                            chunk.data().data(), chunk.size(), options.zstd_level);
    if (ZSTD_isError(n)) {
      throw FileError(path.string(), 0, "", fmt::format("zstd: {}", ZSTD_getErrorName(n)));
    }
    records = {compressed.data(), n};
  }
  ChunkIndex index;
  index.start_time = chunk_has_messages ? chunk_start : 0;
  index.end_time = chunk_has_messages ? chunk_end : 0;
  index.offset = offset;
  index.compression = options.compression;
  index.compressed_size = records.size();
  index.uncompressed_size = chunk.size();
  // The Chunk record's fields, then its records as they are: no copy of megabytes (each fresh
  // buffer of a chunk's size cost a page fault per 4 KiB page).
  head.Clear();
  head.U8(internal::kChunk);
  head.U64(8 + 8 + 8 + 4 + 4 + options.compression.size() + 8 + records.size());
  head.U64(index.start_time);
  head.U64(index.end_time);
  head.U64(chunk.size());
  const uint32_t chunk_crc = Crc32(chunk.data());
  head.U32(chunk_crc);
  head.String(options.compression);
  head.U64(records.size());
  index.length = head.size() + records.size();
  // The message indexes right after the chunk, one per channel, in channel order.
  indexes.Clear();
  for (const auto& [channel, entries] : chunk_messages) {
    Bytes message_index;
    message_index.U16(channel);
    message_index.U32(static_cast<uint32_t>(entries.size() * 16));
    for (const auto& [time, at] : entries) {
      message_index.U64(time);
      message_index.U64(at);
    }
    index.message_index_offsets[channel] = offset + index.length + indexes.size();
    const std::size_t before = indexes.size();
    indexes.Record(internal::kMessageIndex, message_index);
    index.message_index_length += indexes.size() - before;
  }
  Put(head.data());
  if (records.data() == chunk.data().data()) {
    Put(records, chunk_crc);  // uncompressed: the chunk's CRC is theirs
  } else {
    Put(records);
  }
  Put(indexes.data());
  std::fflush(file);  // a complete chunk on disk: recoverable whatever comes next
  chunk_indexes.push_back(std::move(index));
  ++stats.chunk_count;
  chunk.Clear();
  chunk_messages.clear();
  chunk_has_messages = false;
}

void McapWriter::Impl::WriteSummary() {
  Bytes data_end;
  Bytes crc;
  crc.U32(data_crc);
  data_end.Record(internal::kDataEnd, crc);
  Put(data_end.data(), false);
  const uint64_t summary_start = offset;
  Bytes summary;
  std::vector<std::tuple<uint8_t, uint64_t, uint64_t>> groups;  // opcode, start, length
  const auto group = [&](uint8_t opcode, const std::function<void()>& write) {
    const std::size_t before = summary.size();
    write();
    if (summary.size() > before)
      groups.emplace_back(opcode, summary_start + before, summary.size() - before);
  };
  group(internal::kSchema, [&] {
    for (const auto& [id, schema] : schemas)
      summary.Record(internal::kSchema, SchemaContent(schema));
  });
  group(internal::kChannel, [&] {
    for (const auto& [id, channel] : channels) {
      summary.Record(internal::kChannel, ChannelContent(channel));
    }
  });
  group(internal::kChunkIndex, [&] {
    for (const ChunkIndex& i : chunk_indexes) {
      Bytes c, offsets;
      c.U64(i.start_time);
      c.U64(i.end_time);
      c.U64(i.offset);
      c.U64(i.length);
      for (const auto& [channel, at] : i.message_index_offsets) {
        offsets.U16(channel);
        offsets.U64(at);
      }
      c.U32(static_cast<uint32_t>(offsets.size()));
      c.Raw(offsets.data());
      c.U64(i.message_index_length);
      c.String(i.compression);
      c.U64(i.compressed_size);
      c.U64(i.uncompressed_size);
      summary.Record(internal::kChunkIndex, c);
    }
  });
  group(internal::kMetadataIndex, [&] {
    for (const MetadataIndex& i : metadata_indexes) {
      Bytes c;
      c.U64(i.offset);
      c.U64(i.length);
      c.String(i.name);
      summary.Record(internal::kMetadataIndex, c);
    }
  });
  group(internal::kStatistics, [&] {
    Bytes c, counts;
    c.U64(stats.message_count);
    c.U16(static_cast<uint16_t>(schemas.size()));
    c.U32(static_cast<uint32_t>(channels.size()));
    c.U32(0);  // attachments
    c.U32(static_cast<uint32_t>(metadata_indexes.size()));
    c.U32(stats.chunk_count);
    c.U64(stats.message_start_time);
    c.U64(stats.message_end_time);
    for (const auto& [channel, count] : stats.channel_message_counts) {
      counts.U16(channel);
      counts.U64(count);
    }
    c.U32(static_cast<uint32_t>(counts.size()));
    c.Raw(counts.data());
    summary.Record(internal::kStatistics, c);
  });
  const uint64_t summary_offset_start = summary_start + summary.size();
  for (const auto& [opcode, start, length] : groups) {
    Bytes c;
    c.U8(opcode);
    c.U64(start);
    c.U64(length);
    summary.Record(internal::kSummaryOffset, c);
  }
  Bytes footer;
  footer.U8(internal::kFooter);
  footer.U64(8 + 8 + 4);
  footer.U64(summary_start);
  footer.U64(summary_offset_start);
  const uint32_t summary_crc = Crc32(footer.data(), Crc32(summary.data()));
  footer.U32(summary_crc);
  Put(summary.data(), false);
  Put(footer.data(), false);
  Put(internal::kMagic, false);
}

void McapWriter::Close() {
  Impl& w = *impl_;
  if (w.closed) return;
  w.FlushChunk();
  w.WriteSummary();
  w.closed = true;
  const bool failed = std::fclose(w.file) != 0;
  w.file = nullptr;
  if (failed) {
    throw FileError(w.path.string(), 0, "", fmt::format("cannot close: {}", std::strerror(errno)));
  }
}

const McapStatistics& McapWriter::statistics() const { return impl_->stats; }
uint64_t McapWriter::bytes_written() const { return impl_->offset; }

}  // namespace saccade::record
