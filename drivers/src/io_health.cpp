#include "hystlab/drivers/io_health.hpp"

#include <cmath>
#include <string>

namespace hystlab::drivers {
namespace {
class Category final : public std::error_category {
 public:
  const char* name() const noexcept override { return "hystlab.rig"; }
  std::string message(int c) const override {
    switch (static_cast<RigError>(c)) {
      case RigError::timeout:
        return "timeout: no answer from the rig";
      case RigError::exception_response:
        return "the rig answered with a Modbus exception";
      case RigError::connection_lost:
        return "connection to the rig lost";
      case RigError::crc_error:
        return "CRC error on the serial line";
      case RigError::out_of_range:
        return "value outside the register map's range";
      case RigError::protocol_error:
        return "malformed answer from the rig";
      case RigError::not_connected:
        return "not connected to the rig";
      case RigError::stale_data:
        return "the rig's sample counter stopped advancing";
      case RigError::unsupported:
        return "the rig has no such signal";
      case RigError::count_:
        break;
    }
    return "unknown rig error";
  }
};
}  // namespace

const std::error_category& rig_error_category() noexcept {
  static const Category c;
  return c;
}

std::uint64_t IoHealthSnapshot::total_errors() const noexcept {
  std::uint64_t t = 0;
  for (auto e : errors) t += e;
  return t;
}

void IoHealth::record_transaction(bool write, double us) noexcept {
  (write ? writes_ : reads_).fetch_add(1, std::memory_order_relaxed);
  last_us_.store(us, std::memory_order_relaxed);
  total_us_.store(total_us_.load(std::memory_order_relaxed) + us, std::memory_order_relaxed);  // one I/O thread writes
  if (us > max_us_.load(std::memory_order_relaxed)) max_us_.store(us, std::memory_order_relaxed);
  std::size_t b = 0;
  for (double edge = 2.0; us >= edge && b + 1 < kLatencyBuckets; edge *= 2.0) ++b;
  histogram_[b].fetch_add(1, std::memory_order_relaxed);
}

IoHealthSnapshot IoHealth::snapshot() const noexcept {
  IoHealthSnapshot s;
  s.reads = reads_.load(std::memory_order_relaxed);
  s.writes = writes_.load(std::memory_order_relaxed);
  s.reconnects = reconnects_.load(std::memory_order_relaxed);
  s.lost_samples = lost_.load(std::memory_order_relaxed);
  for (std::size_t k = 0; k < kRigErrorCount; ++k) s.errors[k] = errors_[k].load(std::memory_order_relaxed);
  s.last_transaction_us = last_us_.load(std::memory_order_relaxed);
  s.max_transaction_us = max_us_.load(std::memory_order_relaxed);
  s.total_transaction_us = total_us_.load(std::memory_order_relaxed);
  for (std::size_t k = 0; k < kLatencyBuckets; ++k) s.latency_histogram[k] = histogram_[k].load(std::memory_order_relaxed);
  return s;
}

}  // namespace hystlab::drivers
