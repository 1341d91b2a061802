#pragma once
// What the acquisition thread shows the outside world while it runs, without ever waiting:
// a ring of recent samples that any number of readers copy (a seqlock per slot: a reader that
// was overtaken by the writer sees it and skips), and a few relaxed counters.
#include <array>
#include <atomic>
#include <cstdint>
#include <vector>

#include "hystlab/control/values.hpp"

namespace hystlab::daemon {

using LiveSample = control::LiveSample;

class LiveSampleRing {
 public:
  static constexpr std::size_t kCapacity = 1U << 14;  // 16 s at 1 kHz

  // One producer per ring (the rig's thread). Never blocks, never allocates.
  void push(const LiveSample& s) noexcept {
    const std::uint64_t i = head_.load(std::memory_order_relaxed);
    Slot& slot = slots_[i & (kCapacity - 1)];
    slot.seq.store(2 * i + 1, std::memory_order_relaxed);  // odd: being written
    std::atomic_thread_fence(std::memory_order_release);
    slot.v[0].store(s.mono_s, std::memory_order_relaxed);
    slot.v[1].store(s.t, std::memory_order_relaxed);
    slot.v[2].store(s.v[0], std::memory_order_relaxed);
    slot.v[3].store(s.v[1], std::memory_order_relaxed);
    slot.v[4].store(s.v[2], std::memory_order_relaxed);
    slot.run.store(s.run, std::memory_order_relaxed);
    slot.status.store(s.status, std::memory_order_relaxed);
    slot.seq.store(2 * i + 2, std::memory_order_release);
    head_.store(i + 1, std::memory_order_release);
  }
  // Index one past the newest sample.
  [[nodiscard]] std::uint64_t head() const noexcept { return head_.load(std::memory_order_acquire); }
  // Sample i, if it is still in the ring and was not overwritten while being read.
  bool get(std::uint64_t i, LiveSample& out) const noexcept {
    const Slot& slot = slots_[i & (kCapacity - 1)];
    const std::uint64_t s1 = slot.seq.load(std::memory_order_acquire);
    if (s1 != 2 * i + 2) return false;
    out.mono_s = slot.v[0].load(std::memory_order_relaxed);
    out.t = slot.v[1].load(std::memory_order_relaxed);
    out.v[0] = slot.v[2].load(std::memory_order_relaxed);
    out.v[1] = slot.v[3].load(std::memory_order_relaxed);
    out.v[2] = slot.v[4].load(std::memory_order_relaxed);
    out.run = slot.run.load(std::memory_order_relaxed);
    out.status = slot.status.load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    return slot.seq.load(std::memory_order_relaxed) == s1;
  }
  // Copies samples [from, head) taking every stride-th (from is advanced); samples the writer
  // has already overwritten are skipped and counted in *lost.
  std::uint64_t read(std::uint64_t from, std::size_t stride, std::vector<LiveSample>& out, std::uint64_t* lost = nullptr) const {
    const std::uint64_t h = head();
    if (h > kCapacity && from < h - kCapacity + 64) {
      if (lost) *lost += h - kCapacity + 64 - from;
      from = h - kCapacity + 64;  // keep clear of the slots being rewritten
    }
    if (stride == 0) stride = 1;
    LiveSample s;
    std::uint64_t i = from;
    for (; i < h; i += stride)
      if (get(i, s))
        out.push_back(s);
      else if (lost)
        ++*lost;
    return i;
  }

 private:
  struct Slot {
    std::atomic<std::uint64_t> seq{0};
    std::array<std::atomic<double>, 5> v{};
    std::atomic<std::int64_t> run{0};
    std::atomic<std::uint32_t> status{0};
  };
  std::array<Slot, kCapacity> slots_{};
  std::atomic<std::uint64_t> head_{0};
};

// One rig's live view: the sample ring and the acquisition counters (for /metrics).
struct RigLive {
  LiveSampleRing ring;
  std::atomic<std::uint64_t> samples{0}, missed_deadlines{0}, late_wakeups{0};
  std::atomic<std::int64_t> campaign{0}, run{0};
  std::atomic<double> sample_rate_hz{0};
  std::atomic<std::uint8_t> phase{0};  // daemon::CampaignPhase, set by the loop every period
  // Seconds from the newest submission's call to its rig's thread taking the job (-1: none yet).
  std::atomic<double> submit_latency_s{-1};
};

}  // namespace hystlab::daemon
