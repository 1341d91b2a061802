// libFuzzer: the register map loader must refuse any text with MapError, never crash or hang.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "hystlab/protocols/register_map.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto map = hystlab::protocols::RegisterMap::from_json(std::string_view(reinterpret_cast<const char*>(data), size));
    (void)map.measurement_blocks();
  } catch (const hystlab::protocols::MapError&) {
  }
  return 0;
}
