#pragma once
// One record of a controller's sample window (RegisterMap::sample_window): the controller (or
// hystlab-sim) encodes, the host decodes. Each field is encoded as its entry in the map says.
#include <array>
#include <cstdint>
#include <span>
#include <system_error>

#include "hystlab/protocols/register_map.hpp"

namespace hystlab::protocols {

using SignalArray = std::array<double, kSignalCount>;  // indexed by Signal; NaN: not present

// values[field] for every field of the window -> w.record_width words.
std::error_code encode_record(const RegisterMap& m, const SampleWindow& w, const SignalArray& values, std::span<std::uint16_t> words) noexcept;
// w.record_width words -> values[field] for every field (other entries untouched).
std::error_code decode_record(const RegisterMap& m, const SampleWindow& w, std::span<const std::uint16_t> words, SignalArray& values) noexcept;

}  // namespace hystlab::protocols
