#include "hystlab/protocols/protocol_error.hpp"

#include <string>

namespace hystlab::protocols {
namespace {
class Category final : public std::error_category {
 public:
  const char* name() const noexcept override { return "hystlab.protocol"; }
  std::string message(int c) const override {
    switch (static_cast<ProtocolError>(c)) {
      case ProtocolError::out_of_range:
        return "value out of range";
      case ProtocolError::not_finite:
        return "value is not a finite number";
      case ProtocolError::wrong_length:
        return "wrong length (register count or DLC)";
      case ProtocolError::unknown_id:
        return "unknown CAN identifier";
      case ProtocolError::bad_crc:
        return "CRC check failed";
      case ProtocolError::reserved_bits:
        return "reserved bits are set";
    }
    return "unknown protocol error";
  }
};
}  // namespace

const std::error_category& protocol_error_category() noexcept {
  static const Category c;
  return c;
}

}  // namespace hystlab::protocols
