#pragma once
// I/O health of one rig link, kept as EPICS's modbus driver keeps it: counts of reads, writes,
// errors by kind and reconnects, last and max transaction time, and a latency histogram.
// Written by the I/O thread, read by anyone (relaxed atomics: figures, not synchronisation).
#include <array>
#include <atomic>
#include <cstdint>

#include "hystlab/drivers/rig_error.hpp"

namespace hystlab::drivers {

inline constexpr std::size_t kLatencyBuckets = 16;  // bucket k: [2^k, 2^(k+1)) µs; the last is open

struct IoHealthSnapshot {
  std::uint64_t reads = 0, writes = 0, reconnects = 0;
  std::uint64_t lost_samples = 0;                      // gaps in a controller's sample counter that no block read filled
  std::array<std::uint64_t, kRigErrorCount> errors{};  // index = RigError value (0 unused)
  double last_transaction_us = 0, max_transaction_us = 0, total_transaction_us = 0;
  std::array<std::uint64_t, kLatencyBuckets> latency_histogram{};
  [[nodiscard]] std::uint64_t errors_of(RigError e) const noexcept { return errors[static_cast<std::size_t>(e)]; }
  [[nodiscard]] std::uint64_t total_errors() const noexcept;
};

class IoHealth {
 public:
  void record_transaction(bool write, double micros) noexcept;
  void record_error(RigError e) noexcept { errors_[static_cast<std::size_t>(e)].fetch_add(1, std::memory_order_relaxed); }
  void record_reconnect() noexcept { reconnects_.fetch_add(1, std::memory_order_relaxed); }
  void record_lost(std::uint64_t n) noexcept { lost_.fetch_add(n, std::memory_order_relaxed); }
  [[nodiscard]] IoHealthSnapshot snapshot() const noexcept;

 private:
  std::atomic<std::uint64_t> reads_{0}, writes_{0}, reconnects_{0}, lost_{0};
  std::array<std::atomic<std::uint64_t>, kRigErrorCount> errors_{};
  std::atomic<double> last_us_{0}, max_us_{0}, total_us_{0};
  std::array<std::atomic<std::uint64_t>, kLatencyBuckets> histogram_{};
};

}  // namespace hystlab::drivers
