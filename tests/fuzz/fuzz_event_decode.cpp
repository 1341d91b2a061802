// libFuzzer: any bytes as a stored event (its kind from the first byte, its detail the rest);
// decode never crashes, and what decodes re-encodes to a detail that decodes to the same JSON.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "hystlab/domain/events.hpp"

namespace domain = hystlab::domain;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const auto& kinds = domain::event_kinds();
  const std::string_view kind = kinds[data[0] % kinds.size()].kind;
  const std::string_view detail(reinterpret_cast<const char*>(data + 1), size - 1);
  std::string error;
  const auto e = domain::decode_event(kind, detail, error);
  if (!e) {
    if (error.empty()) std::abort();  // every kind listed is known: a failure says why
    return 0;
  }
  if (domain::kind_of(*e) != kind) std::abort();
  const std::string again = domain::encode(*e);
  const auto e2 = domain::decode_event(kind, again, error);
  if (!e2 || domain::encode(*e2) != again) std::abort();
  return 0;
}
