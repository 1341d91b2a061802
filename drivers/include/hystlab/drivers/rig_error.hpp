#pragma once
// Typed errors of rig I/O: what the caller can act on (retry, hold, fail the campaign).
#include <cstddef>
#include <system_error>

namespace hystlab::drivers {

enum class RigError {
  timeout = 1,         // no answer within the response timeout
  exception_response,  // the device answered with a Modbus exception
  connection_lost,     // the link dropped (or could not be made)
  crc_error,           // an RTU frame failed its CRC
  out_of_range,        // a value outside the map's range (read) or the type's (write)
  protocol_error,      // a malformed answer or frame
  not_connected,       // no link yet, or waiting for the next reconnect attempt
  stale_data,          // the rig's sample counter stopped advancing
  unsupported,         // this rig has no such signal
  count_
};
inline constexpr std::size_t kRigErrorCount = static_cast<std::size_t>(RigError::count_);

[[nodiscard]] const std::error_category& rig_error_category() noexcept;
[[nodiscard]] inline std::error_code make_error_code(RigError e) noexcept { return {static_cast<int>(e), rig_error_category()}; }

}  // namespace hystlab::drivers

template <>
struct std::is_error_code_enum<hystlab::drivers::RigError> : std::true_type {};
