// libFuzzer: decoding register words with any entry layout; encode(decode(x)) must round-trip.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "hystlab/protocols/register_map.hpp"

using namespace hystlab::protocols;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 6) return 0;
  MapEntry e;
  e.table = ModbusTable::input_register;
  e.type = static_cast<ValueType>(1 + data[0] % 5);  // the register types
  e.word_order = (data[1] & 1) ? WordOrder::swapped : WordOrder::big;
  e.scale = (data[1] & 2) ? 0.001 : 1.0;
  const std::uint16_t words[2] = {static_cast<std::uint16_t>(data[2] << 8 | data[3]), static_cast<std::uint16_t>(data[4] << 8 | data[5])};
  double v = 0;
  if (decode(e, words, v)) return 0;
  std::uint16_t back[2] = {0, 0};
  if (encode(e, v, back)) std::abort();  // a decoded value must encode
  if (e.type != ValueType::float32 && e.scale == 1.0 && (back[0] != words[0] || (e.width() == 2 && back[1] != words[1])))
    std::abort();  // integers round-trip exactly
  return 0;
}
