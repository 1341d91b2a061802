#pragma once
// A bounded single-producer/single-consumer ring: the acquisition thread pushes without ever
// blocking or allocating (a full ring says so, and the caller counts it); the writer drains.
#include <atomic>
#include <cstddef>
#include <vector>

namespace hystlab::db {

template <class T>
class SpscRing {
 public:
  explicit SpscRing(std::size_t capacity_pow2) : buf_(capacity_pow2), mask_(capacity_pow2 - 1) {}
  [[nodiscard]] std::size_t capacity() const noexcept { return buf_.size(); }
  bool try_push(const T& v) noexcept {
    const std::size_t h = head_.load(std::memory_order_relaxed);
    if (h - tail_.load(std::memory_order_acquire) == buf_.size()) return false;
    buf_[h & mask_] = v;
    head_.store(h + 1, std::memory_order_release);
    return true;
  }
  // Moves up to max items into out (appending); returns how many.
  std::size_t drain(std::vector<T>& out, std::size_t max) {
    const std::size_t t = tail_.load(std::memory_order_relaxed);
    const std::size_t n = std::min(max, head_.load(std::memory_order_acquire) - t);
    for (std::size_t k = 0; k < n; ++k) out.push_back(buf_[(t + k) & mask_]);
    tail_.store(t + n, std::memory_order_release);
    return n;
  }
  [[nodiscard]] std::size_t size() const noexcept { return head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire); }

 private:
  std::vector<T> buf_;
  std::size_t mask_;
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
};

}  // namespace hystlab::db
