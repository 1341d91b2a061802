#pragma once
// CRC-16/MODBUS of an RTU frame (polynomial 0xA001 reflected, initial 0xFFFF), sent low byte first.
#include <cstdint>
#include <span>

namespace hystlab::protocols {

[[nodiscard]] constexpr std::uint16_t crc16_modbus(std::span<const std::uint8_t> bytes) noexcept {
  std::uint16_t crc = 0xFFFF;
  for (const std::uint8_t b : bytes) {
    crc = static_cast<std::uint16_t>(crc ^ b);
    for (int k = 0; k < 8; ++k) crc = static_cast<std::uint16_t>((crc & 1U) ? (crc >> 1) ^ 0xA001U : crc >> 1);
  }
  return crc;
}

}  // namespace hystlab::protocols
