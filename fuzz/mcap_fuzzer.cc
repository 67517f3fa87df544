// libFuzzer target: any bytes as an MCAP file -> record::McapReader, then every message, each
// decoded with its channel's ros2msg schema (record::RosMessageDecoder). A recording may be cut
// short or damaged anywhere; the reader must never crash, never allocate what the file only
// claims, and fail only with saccade::FileError (naming the file and byte); a schema or a
// message that is not what it claims only with InvalidArgument. What it reads of a file cut
// short it must read the same way twice. Built and run by fuzz/run.sh; the seeds are small
// recordings saccade wrote (zstd and uncompressed) and one @mcap/core wrote with ROS 2
// messages (tests/record/mcap_reference/ros2_sample.mjs).

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/record/mcap.h"
#include "saccade/record/ros_message.h"

namespace {

void Check(bool condition) {
  if (!condition) std::abort();  // libFuzzer reports it with the input
}

uint64_t CountMessages(const saccade::record::McapReader& reader) {
  uint64_t n = 0;
  reader.ForEachMessage([&](const saccade::record::McapMessage& m) {
    Check(m.data.size() < (uint64_t{1} << 32));
    ++n;
    return true;
  });
  return n;
}

// Every message of a channel with a ros2msg schema, decoded by it.
void DecodeMessages(const saccade::record::McapReader& reader) {
  std::map<uint16_t, std::optional<saccade::record::RosMessageDecoder>> decoders;
  for (const auto& [id, channel] : reader.channels()) {
    const auto schema = reader.schemas().find(channel.schema_id);
    if (schema == reader.schemas().end() || schema->second.encoding != "ros2msg") continue;
    try {
      decoders.emplace(
          id, saccade::record::RosMessageDecoder(schema->second.name, schema->second.data));
    } catch (const saccade::InvalidArgument&) {
      // A definition that is not one: named, as it must be.
    }
  }
  reader.ForEachMessage([&](const saccade::record::McapMessage& m) {
    const auto decoder = decoders.find(m.channel_id);
    if (decoder == decoders.end() || !decoder->second) return true;
    std::vector<std::span<const uint8_t>> blobs;
    try {
      decoder->second->Decode(m.data, &blobs);
      for (const auto& blob : blobs) {
        Check(blob.data() >= m.data.data() &&
              blob.data() + blob.size() <= m.data.data() + m.data.size());
      }
    } catch (const saccade::InvalidArgument&) {
    }
    return true;
  });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const char* tmp = std::getenv("TMPDIR");
  const std::filesystem::path file = std::filesystem::path(tmp ? tmp : "/tmp") /
                                     ("mcap_fuzz_" + std::to_string(::getpid()) + ".mcap");
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(data), size);
  try {
    const saccade::record::McapReader reader(file);
    const uint64_t first = CountMessages(reader);
    Check(CountMessages(reader) == first);
    // A recovered file's statistics are what its scan counted: the same messages.
    if (reader.recovered()) Check(reader.statistics().message_count == first);
    DecodeMessages(reader);
  } catch (const saccade::FileError&) {
    // A clear error for a damaged file: what the reader must do.
  }
  return 0;
}
