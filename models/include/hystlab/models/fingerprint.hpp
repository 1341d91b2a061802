#pragma once
// FNV-1a, 64 bits: an identity of a table or parameter set (the FMU's GUID, a saved state's
// owner), not a signature. Chained: fnv1a64(b, fnv1a64(a)) is the hash of a followed by b.
#include <cstdint>
#include <string_view>

namespace hystlab::models {

inline constexpr std::uint64_t kFnvBasis = 0xcbf29ce484222325ULL;

[[nodiscard]] inline std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t basis = kFnvBasis) {
  std::uint64_t h = basis;
  for (const char c : bytes) {
    h ^= static_cast<std::uint8_t>(c);
    h *= 0x100000001b3ULL;
  }
  return h;
}

}  // namespace hystlab::models
