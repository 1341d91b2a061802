#pragma once
// Typed decode/encode errors of the rig protocols.
#include <system_error>

namespace hystlab::protocols {

enum class ProtocolError {
  out_of_range = 1,  // a value outside what the type or the map allows
  not_finite,        // NaN or infinity
  wrong_length,      // register count or CAN DLC does not match the layout
  unknown_id,        // CAN identifier not in the protocol
  bad_crc,           // RTU frame check failed
  reserved_bits,     // bits the layout defines as zero are set
};

[[nodiscard]] const std::error_category& protocol_error_category() noexcept;
[[nodiscard]] inline std::error_code make_error_code(ProtocolError e) noexcept { return {static_cast<int>(e), protocol_error_category()}; }

}  // namespace hystlab::protocols

template <>
struct std::is_error_code_enum<hystlab::protocols::ProtocolError> : std::true_type {};
