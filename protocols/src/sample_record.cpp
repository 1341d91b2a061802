#include "hystlab/protocols/sample_record.hpp"

namespace hystlab::protocols {

std::error_code encode_record(const RegisterMap& m, const SampleWindow& w, const SignalArray& values, std::span<std::uint16_t> words) noexcept {
  if (words.size() < static_cast<std::size_t>(w.record_width)) return ProtocolError::wrong_length;
  std::size_t at = 0;
  for (const Signal s : w.fields) {
    const MapEntry* e = m.find(s);
    if (!e) return ProtocolError::wrong_length;  // a window not parsed from this map
    if (auto ec = encode(*e, values[static_cast<std::size_t>(s)], words.subspan(at))) return ec;
    at += static_cast<std::size_t>(e->width());
  }
  return {};
}

std::error_code decode_record(const RegisterMap& m, const SampleWindow& w, std::span<const std::uint16_t> words, SignalArray& values) noexcept {
  if (words.size() < static_cast<std::size_t>(w.record_width)) return ProtocolError::wrong_length;
  std::size_t at = 0;
  for (const Signal s : w.fields) {
    const MapEntry* e = m.find(s);
    if (!e) return ProtocolError::wrong_length;
    if (auto ec = decode(*e, words.subspan(at), values[static_cast<std::size_t>(s)])) return ec;
    at += static_cast<std::size_t>(e->width());
  }
  return {};
}

}  // namespace hystlab::protocols
