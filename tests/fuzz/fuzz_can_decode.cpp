// libFuzzer: any 16 bytes as a CAN frame; decode never crashes, and what decodes re-encodes to it.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "hystlab/protocols/can_protocol.hpp"

namespace can = hystlab::protocols::can;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < sizeof(can_frame) + 1) return 0;
  can_frame f{};
  std::memcpy(&f, data, sizeof f);
  const int node = 1 + data[sizeof f] % 127;
  if (f.can_dlc > 8) return 0;  // the kernel never delivers these
  can::Message m;
  if (can::decode(f, node, m)) return 0;
  can_frame g{};
  if (can::encode(m, node, g)) std::abort();
  if (g.can_id != f.can_id || g.can_dlc != f.can_dlc) std::abort();
  return 0;
}
