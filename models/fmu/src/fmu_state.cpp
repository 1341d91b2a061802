#include "fmu_state.hpp"

#include <bit>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string_view>

namespace hystlab::fmu {
namespace {
constexpr std::string_view kMagic{"HYSTLAB-FMU-STATE\0", 18};
constexpr std::uint32_t kStateVersion = 1;
constexpr std::uint32_t kMaxGuid = 256;
constexpr std::uint32_t kMaxNumbers = 1U << 24;

void put_u32(std::vector<char>& out, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<char>((v >> (8 * k)) & 0xffU));
}

void put_u64(std::vector<char>& out, std::uint64_t v) {
  for (int k = 0; k < 8; ++k) out.push_back(static_cast<char>((v >> (8 * k)) & 0xffU));
}

// Reads from the front of a byte span; every read checks the length first.
struct Reader {
  std::span<const char> rest;
  std::uint64_t take(std::size_t n, const char* what) {
    if (rest.size() < n) throw std::invalid_argument(std::string("FMU state: truncated (") + what + ")");
    std::uint64_t v = 0;
    for (std::size_t k = 0; k < n; ++k) v |= static_cast<std::uint64_t>(static_cast<unsigned char>(rest[k])) << (8 * k);
    rest = rest.subspan(n);
    return v;
  }
};
}  // namespace

std::vector<char> encode_state(const StateRecord& r) {
  std::vector<char> out(kMagic.begin(), kMagic.end());
  put_u32(out, kStateVersion);
  put_u32(out, static_cast<std::uint32_t>(r.guid.size()));
  out.insert(out.end(), r.guid.begin(), r.guid.end());
  put_u32(out, static_cast<std::uint32_t>(r.numbers.size()));
  for (const double d : r.numbers) put_u64(out, std::bit_cast<std::uint64_t>(d));
  return out;
}

StateRecord decode_state(std::span<const char> bytes) {
  if (bytes.size() < kMagic.size() || std::memcmp(bytes.data(), kMagic.data(), kMagic.size()) != 0)
    throw std::invalid_argument("FMU state: not a serialized hystlab FMU state");
  Reader in{bytes.subspan(kMagic.size())};
  const auto version = in.take(4, "version");
  if (version != kStateVersion)
    throw std::invalid_argument("FMU state: version " + std::to_string(version) + " (this FMU reads version " + std::to_string(kStateVersion) + ")");
  const auto glen = in.take(4, "GUID length");
  if (glen > kMaxGuid) throw std::invalid_argument("FMU state: a GUID of " + std::to_string(glen) + " bytes");
  if (in.rest.size() < glen) throw std::invalid_argument("FMU state: truncated (GUID)");
  StateRecord r;
  r.guid.assign(in.rest.data(), static_cast<std::size_t>(glen));
  in.rest = in.rest.subspan(static_cast<std::size_t>(glen));
  const auto count = in.take(4, "number count");
  if (count > kMaxNumbers || in.rest.size() != count * 8)
    throw std::invalid_argument("FMU state: " + std::to_string(in.rest.size()) + " bytes for " + std::to_string(count) + " numbers");
  r.numbers.reserve(static_cast<std::size_t>(count));
  for (std::uint64_t k = 0; k < count; ++k) r.numbers.push_back(std::bit_cast<double>(in.take(8, "numbers")));
  return r;
}

}  // namespace hystlab::fmu
