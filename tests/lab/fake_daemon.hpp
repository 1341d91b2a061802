#pragma once
// A fake daemon for the lab's tests (as tests/web/test_control_fake.cpp's): rigs with names the
// test picks, a supervision state it sets, and a live ring fed at 1 kHz by a thread of its own,
// as a rig's acquisition thread would. It notes when read_live is called, so that a test can see
// the publisher keep its pace whatever the broker does.
#include <atomic>
#include <chrono>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "hystlab/control/daemon_interface.hpp"

namespace hystlab::test_support {

class FakeDaemon final : public control::DaemonInterface {
 public:
  static constexpr std::uint64_t kRing = 4096;  // 4 s at 1 kHz: a publisher stalled longer loses samples

  FakeDaemon(std::vector<std::string> rigs, std::string db) : names_(std::move(rigs)), db_(std::move(db)), ring_(names_.size()) {
    for (auto& r : ring_) r.resize(kRing);
    feeder_ = std::thread([this] { feed(); });
  }
  ~FakeDaemon() override {
    stop_ = true;
    feeder_.join();
  }
  FakeDaemon(const FakeDaemon&) = delete;
  FakeDaemon& operator=(const FakeDaemon&) = delete;

  // What the test sets.
  void set_state(const std::string& state, bool latched, std::int64_t campaign = 0, std::int64_t run = 0) {
    std::lock_guard lk(mu_);
    state_ = state, latched_ = latched, campaign_ = campaign, run_ = run;
  }
  // The longest time between two read_live calls on rig 0 since the last call (seconds).
  double max_read_gap_s() {
    std::lock_guard lk(mu_);
    const double g = max_gap_s_;
    max_gap_s_ = 0;
    return g;
  }
  std::uint64_t reads() const { return reads_; }

  std::size_t rig_count() const noexcept override { return names_.size(); }
  control::RigInfo rig_info(std::size_t k) const override {
    return {static_cast<std::int64_t>(k + 1), names_.at(k), "fake", k == 1 ? domain::RigKind::shaker : domain::RigKind::load_frame, true};
  }
  control::RigSupervision rig_supervision(std::size_t k) const override {
    std::lock_guard lk(mu_);
    control::RigSupervision s;
    s.state = k == 0 ? state_ : "idle";
    s.latched = k == 0 && latched_;
    s.latch_reason = s.latched ? "operator e-stop" : "";
    return s;
  }
  control::LinkHealth rig_health(std::size_t) const override { return {}; }
  control::AcquisitionCounters rig_counters(std::size_t k) const override {
    std::lock_guard lk(mu_);
    control::AcquisitionCounters a;
    a.samples = head_;
    if (k == 0) a.campaign = campaign_, a.run = run_, a.sample_rate_hz = run_ != 0 ? 1000 : 0, a.phase = run_ != 0 ? "ramping" : "none";
    return a;
  }
  std::size_t rig_index(const std::string&, std::string_view) const override { return 0; }
  control::CommandOutcome rig_command(std::size_t, control::RigCommand) override { throw std::logic_error("the publisher never commands a rig"); }
  std::uint64_t live_head(std::size_t) const noexcept override { return head_; }
  std::uint64_t read_live(std::size_t k, std::uint64_t from, std::size_t stride, std::vector<control::LiveSample>& out, std::uint64_t* lost) const override {
    std::lock_guard lk(mu_);
    if (k == 0) {
      const auto now = std::chrono::steady_clock::now();
      if (reads_ > 0) max_gap_s_ = std::max(max_gap_s_, std::chrono::duration<double>(now - last_read_).count());
      last_read_ = now;
      ++reads_;
    }
    const std::uint64_t head = head_;
    std::uint64_t start = from;
    if (head - start > kRing) {
      if (lost != nullptr) *lost += head - kRing - start;
      start = head - kRing;
    }
    for (std::uint64_t i = start; i < head; i += stride) out.push_back(ring_[k][i % kRing]);
    return head;
  }
  std::int64_t submit(const std::string&, const nlohmann::json&) override { throw std::logic_error("the publisher never submits"); }
  control::PlanPreview preview(const std::string&, const nlohmann::json&, models::HysteresisModel*) const override { return {}; }
  control::CommandOutcome command(std::int64_t, control::CampaignCommand) override { throw std::logic_error("the publisher never commands a campaign"); }
  void set_record(std::int64_t, const nlohmann::json&) override { throw std::logic_error("the publisher never writes"); }
  control::WriterCounters writer() const override { return {}; }
  double uptime_s() const noexcept override { return 1; }
  std::string db_path() const override { return db_; }
  void keep_off_acquisition_cpu(bool) const noexcept override {}

 private:
  // Every rig a sample each millisecond on absolute deadlines; rig time is index / 1000.
  void feed() {
    auto next = std::chrono::steady_clock::now();
    while (!stop_) {
      next += std::chrono::milliseconds(1);
      std::this_thread::sleep_until(next);
      std::lock_guard lk(mu_);
      const double mono = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
      for (auto& r : ring_) {
        const double t = static_cast<double>(head_) / 1000.0;
        r[head_ % kRing] = control::LiveSample{mono, t, {t, 2 * t, 3 * t}, run_, 5};
      }
      ++head_;
    }
  }

  std::vector<std::string> names_;
  std::string db_;
  mutable std::mutex mu_;
  std::vector<std::vector<control::LiveSample>> ring_;
  std::atomic<std::uint64_t> head_{0};
  std::string state_ = "idle";
  bool latched_ = false;
  std::int64_t campaign_ = 0, run_ = 0;
  mutable std::chrono::steady_clock::time_point last_read_{};
  mutable double max_gap_s_ = 0;
  mutable std::atomic<std::uint64_t> reads_{0};
  std::atomic<bool> stop_{false};
  std::thread feeder_;
};

}  // namespace hystlab::test_support
