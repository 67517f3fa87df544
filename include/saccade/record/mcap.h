#pragma once
// MCAP files (https://mcap.dev/spec, major version 0): the container ROS 2's rosbag2, Foxglove
// and Lichtblick read. No C++ MCAP library is packaged for Debian 12, so this is written from the
// specification: McapWriter writes messages into chunks (zstd-compressed or not), each followed
// by its message indexes and flushed whole to the file, then a summary (schemas, channels, chunk
// indexes, statistics, summary offsets) and the footer; McapReader reads a file back, through
// its summary, or chunk by chunk from the start when the file was cut short (a recorder killed
// mid-run: every complete chunk is recovered, as `mcap recover` does).
//
// Times are uint64 nanoseconds (saccade: simulated time from 0, or the wall clock). Both
// classes are used from one thread at a time.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace saccade::record {

struct McapSchema {
  uint16_t id = 0;       ///< >= 1, unique in the file
  std::string name;      ///< "sensor_msgs/msg/Image"
  std::string encoding;  ///< "ros2msg" (the .msg text), or "" for none
  std::string data;      ///< the schema text
};

struct McapChannel {
  uint16_t id = 0;
  uint16_t schema_id = 0;        ///< 0: no schema
  std::string topic;             ///< "/saccade/left/image_raw"
  std::string message_encoding;  ///< "cdr" for ROS 2 messages
  std::map<std::string, std::string> metadata;
};

/// A Metadata record: a name and string pairs (saccade: the run's head, scene and pipeline).
struct McapMetadata {
  std::string name;
  std::map<std::string, std::string> values;
};

/// One message as read: `data` points into the reader's buffer (valid during the callback).
struct McapMessage {
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time = 0;      ///< ns: when it was recorded
  uint64_t publish_time = 0;  ///< ns: when it was captured (its stamp)
  std::span<const uint8_t> data;
};

/// What a file holds (its Statistics record, or counted while reading).
struct McapStatistics {
  uint64_t message_count = 0;
  uint32_t chunk_count = 0;
  uint64_t message_start_time = 0, message_end_time = 0;
  std::map<uint16_t, uint64_t> channel_message_counts;
};

struct McapWriterOptions {
  std::string compression = "zstd";  ///< "zstd" or "" (none)
  /// -7 .. -1: zstd's fast levels (less compression, several times faster); 1 .. 19.
  int zstd_level = 1;
  /// A chunk is closed and written once it holds this many bytes (uncompressed) or spans this
  /// much log time, whichever comes first: a recording killed at any moment loses at most the
  /// open chunk, so at most this long of the run.
  uint64_t chunk_bytes = 4 << 20;
  double chunk_seconds = 1.0;
  std::string profile = "ros2";  ///< the Header's profile
  std::string library = "saccade";
};

/// Writes an MCAP file. Create writes the magic and the header; Close the rest. A writer
/// destroyed without Close closes the file as it is (a reader recovers its complete chunks).
class McapWriter {
 public:
  /// Creates (replaces) `path`. Throws saccade::FileError when it cannot be written and
  /// InvalidArgument for options out of range.
  McapWriter(const std::filesystem::path& path, McapWriterOptions options = {});
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// Registers a schema (its id given by the writer, from 1). Written into the next chunk.
  uint16_t AddSchema(const std::string& name, const std::string& encoding, const std::string& data);
  /// Registers a channel on a schema AddSchema returned (0: none). Throws InvalidArgument for
  /// an unknown schema id.
  uint16_t AddChannel(uint16_t schema_id, const std::string& topic,
                      const std::string& message_encoding,
                      const std::map<std::string, std::string>& metadata = {});
  /// Appends a message on a channel AddChannel returned; its sequence is the channel's count.
  /// Throws InvalidArgument for an unknown channel, FileError when the file cannot be written.
  void Write(uint16_t channel_id, uint64_t log_time, uint64_t publish_time,
             std::span<const uint8_t> data);
  /// Writes a Metadata record (after the open chunk, which it closes), indexed in the summary.
  void AddMetadata(const std::string& name, const std::map<std::string, std::string>& values);
  /// Writes the open chunk, the summary and the footer, and closes the file. Idempotent.
  void Close();

  const McapStatistics& statistics() const;
  uint64_t bytes_written() const;  ///< of the file so far

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Reads an MCAP file. The constructor checks the leading magic and header and, when the file
/// is complete, reads its summary; a file cut short (no footer) is read from the start, chunk
/// by chunk, up to the last complete record (`recovered()` says so).
class McapReader {
 public:
  /// Throws saccade::FileError naming the file and what is wrong: not found, not an MCAP file
  /// (its first bytes), a record that runs past the end, a bad CRC, an unknown compression.
  explicit McapReader(const std::filesystem::path& path);
  ~McapReader();
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  const std::string& profile() const;
  const std::string& library() const;
  const std::map<uint16_t, McapSchema>& schemas() const;
  const std::map<uint16_t, McapChannel>& channels() const;
  /// The Metadata records, in file order.
  const std::vector<McapMetadata>& metadata() const;
  /// The file's Statistics record, or (cut short) what reading the data section found.
  const McapStatistics& statistics() const;
  /// True when the file had no footer (a recording cut short): what it holds was recovered
  /// from its complete chunks; `lost_bytes()` were after the last of them.
  bool recovered() const;
  uint64_t lost_bytes() const;

  /// Every message in file order (chunks in turn); stops early when `visit` returns false.
  /// Throws FileError as the constructor.
  void ForEachMessage(const std::function<bool(const McapMessage&)>& visit) const;

  /// The messages one at a time, in file order (a generator's state, as Python's Reader).
  class Cursor {
   public:
    virtual ~Cursor() = default;
    /// The next message, its data valid until the next call; false after the last (and for a
    /// file cut short, after the last complete chunk). Throws FileError as the constructor.
    virtual bool Next(McapMessage* message) = 0;
  };
  /// A cursor before the first message; it reads the file anew and may outlive the reader.
  std::unique_ptr<Cursor> Messages() const;

 private:
  struct Impl;
  class MessageCursor;
  std::shared_ptr<Impl> impl_;
};

}  // namespace saccade::record
