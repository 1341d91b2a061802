#pragma once
// The GUID of an FMU: a fingerprint of the element's canonical document. Instantiate checks it
// against the resources, and a serialized state carries it, so a state blob from another table is
// refused by name. Two 64-bit FNV-1a hashes with different bases (an identity, not a signature).
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

#include "hystlab/models/fingerprint.hpp"

namespace hystlab::fmu {

inline std::string element_guid(std::string_view canonical_json) {
  const std::uint64_t a = models::fnv1a64(canonical_json), b = models::fnv1a64(canonical_json, 0x84222325cbf29ce4ULL);
  char buf[48];
  std::snprintf(buf, sizeof buf, "{%08x-%04x-%04x-%04x-%012llx}", static_cast<unsigned>(a >> 32), static_cast<unsigned>((a >> 16) & 0xffffU),
                static_cast<unsigned>(a & 0xffffU), static_cast<unsigned>(b >> 48), static_cast<unsigned long long>(b & 0xffffffffffffULL));
  return buf;
}

}  // namespace hystlab::fmu
