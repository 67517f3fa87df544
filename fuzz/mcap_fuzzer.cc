// libFuzzer target: any bytes as an MCAP file -> record::McapReader, then every message. A
// recording may be cut short or damaged anywhere; the reader must never crash, never allocate
// what the file only claims, and fail only with saccade::FileError (naming the file and byte).
// What it reads of a file cut short it must read the same way twice. Built and run by
// fuzz/run.sh; the seeds are small recordings saccade wrote (zstd and uncompressed).

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "saccade/core/error.h"
#include "saccade/record/mcap.h"

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
  } catch (const saccade::FileError&) {
    // A clear error for a damaged file: what the reader must do.
  }
  return 0;
}
