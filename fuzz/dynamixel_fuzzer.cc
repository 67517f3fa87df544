// libFuzzer target: bytes from a servo bus -> dxl::PacketParser, fed in chunks whose sizes the
// input chooses (its first byte). A serial line delivers noise, truncated and corrupted
// packets in any split; the parser must never crash, and every packet it returns must be one
// that encodes back to a packet it parses to the same value (header, ID, LEN and CRC right).
// Built and run by fuzz/run.sh.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "saccade/hw/dynamixel_protocol.h"

namespace dxl = saccade::hw::dxl;

namespace {

void Check(bool condition) {
  if (!condition) std::abort();  // libFuzzer reports it with the input
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  if (size < 1 || size > 8192) return 0;
  const std::size_t chunk = 1 + data[0] % 64;  // how the bytes arrive
  ++data;
  --size;
  dxl::PacketParser parser;
  std::vector<dxl::Packet> packets;
  for (std::size_t i = 0; i < size; i += chunk) {
    parser.Feed(data + i, std::min(chunk, size - i));
    while (auto packet = parser.Next()) packets.push_back(*packet);
  }
  Check(parser.crc_errors() >= 0 && parser.discarded_bytes() >= 0);
  Check(parser.packets() == static_cast<int64_t>(packets.size()));
  for (const dxl::Packet& packet : packets) {
    // The packet as a servo would send it again: the parser must read back the same.
    dxl::PacketParser again;
    Check(again.Feed(dxl::EncodePacket(packet)) == 1);
    const auto back = again.Next();
    Check(back.has_value() && *back == packet);
  }
  return 0;
}
