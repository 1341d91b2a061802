// sine campaigns on a shaker: each frequency is driven for settle_cycles, then measured for
// measured_cycles; amplitude and phase of base and mass motion come from a least-squares sine
// fit, and the transmissibility point is stored as it comes.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "acquisition_loop.hpp"
#include "hystlab/models/sine_fit.hpp"

namespace hystlab::daemon {
namespace {

class SineStrategy final : public Strategy {
 public:
  explicit SineStrategy(const Plan& p) : plan_(p) {}

  bool on_shaker(Loop& L, const drivers::ShakerSample& s) override {
    if (!started_) return start_step(L, s.time_s);
    if (s.time_s >= t_measure_) {
      t_.push_back(s.time_s);
      base_.push_back(s.base_displacement_mm);
      mass_.push_back(s.mass_displacement_mm);
    }
    if (s.time_s < t_end_) return true;
    if (const std::string hole = window_hole(plan_.frequencies_hz[k_]); !hole.empty()) return retake(L, s.time_s, hole);
    if (!store_point(L)) return false;
    ++k_;
    retakes_ = 0;
    started_ = false;
    return true;
  }

  // The step is taken again from its start, at the next sample: on the rig's clock, as every
  // window is (a shaker's samples may be on the controller's clock, behind the loop's).
  void on_resume(Loop&, double, bool) override { started_ = false; }

  [[nodiscard]] bool done() const override { return k_ >= plan_.frequencies_hz.size(); }

 private:
  bool start_step(Loop& L, double t) {
    const double f = plan_.frequencies_hz[k_];
    if (auto ec = L.ctx.rig.command_shaker(f, plan_.amplitude_mm, true)) {
      L.ctx.supervisor.hold(t, "shaker command refused: no drive");
      L.end(CampaignEnd::failed, "shaker command refused: " + ec.message());
      return false;
    }
    started_ = true;
    t_measure_ = t + plan_.settle_cycles / f;
    t_end_ = t_measure_ + plan_.measured_cycles / f;
    t_.clear(), base_.clear(), mass_.clear();
    return true;
  }

  // A measurement window with too little in it (a stalled host, a lost link) is taken again, up
  // to kMaxRetakes times, and the campaign fails only then. The fit is a least-squares sine at
  // the known frequency on the samples' own times, so a hole biases nothing; what it needs is
  // the signal's rate, not the loop's: 8 samples a cycle, and at least half of the window
  // sampled (a gap over a quarter cycle counts as unsampled). A starved 2-core VM polled the
  // shaker at 170 Hz with 0.6 s stalls; judging by the longest gap, 10 Hz never passed there.
  std::string window_hole(double f) const {
    const double window = t_end_ - t_measure_, needed = 8.0 * plan_.measured_cycles;
    double holes = 0, longest = 0, prev = t_measure_;
    for (const double t : t_) {  // the window's stretches between samples, its edges included
      const double gap = std::min(t, t_end_) - std::max(prev, t_measure_);
      longest = std::max(longest, gap);
      if (gap > 0.25 / f) holes += gap;
      prev = t;
    }
    char buf[160];
    if (static_cast<double>(t_.size()) < needed)
      std::snprintf(buf, sizeof buf, "%zu samples, %.0f needed", t_.size(), needed);
    else if (holes > 0.5 * window)
      std::snprintf(buf, sizeof buf, "%.0f of its %.0f ms in gaps (the longest %.0f ms)", holes * 1e3, window * 1e3, longest * 1e3);
    else
      return {};
    return buf;
  }

  bool retake(Loop& L, double t, const std::string& hole) {
    const double f = plan_.frequencies_hz[k_];
    if (++retakes_ > kMaxRetakes) {
      L.ctx.supervisor.hold(t, "no complete measurement: no drive");
      char buf[200];
      std::snprintf(buf, sizeof buf, "the measurement window at %g Hz was incomplete %d times (last: %s)", f, kMaxRetakes + 1, hole.c_str());
      L.end(CampaignEnd::failed, buf);
      return false;
    }
    L.event("retake", {{"frequency_hz", f}, {"why", hole}, {"attempt", retakes_ + 1}});
    return start_step(L, t);
  }

  bool store_point(Loop& L) {
    const double f = plan_.frequencies_hz[k_];
    const models::SineFit b = models::fit_sine(t_, base_, f), m = models::fit_sine(t_, mass_, f);
    if (!b.ok || !m.ok || b.amplitude <= 0) {
      L.ctx.supervisor.hold(t_end_, "no fit: no drive");
      L.end(CampaignEnd::failed, "too few samples to fit the sine at " + std::to_string(f) + " Hz");
      return false;
    }
    const double ratio = m.amplitude / b.amplitude, phase = std::remainder(m.phase_rad - b.phase_rad, 2 * std::numbers::pi);
    const auto run = L.result.run_id, id = L.job.id;
    const std::string now = L.ctx.now_iso();
    L.ctx.writer.post([run, f, b, m, ratio, phase, id, now](db::Store& st) {
      st.add_transmissibility(run, f, b.amplitude, m.amplitude, ratio, phase);
      st.add_event(id, "transmissibility", nlohmann::json{{"frequency_hz", f}, {"ratio", ratio}, {"phase_rad", phase}}.dump(), now);
    });
    return true;
  }

  const Plan& plan_;
  static constexpr int kMaxRetakes = 3;
  std::size_t k_ = 0;
  int retakes_ = 0;
  bool started_ = false;
  double t_measure_ = 0, t_end_ = 0;
  std::vector<double> t_, base_, mass_;
};
}  // namespace

std::unique_ptr<Strategy> make_sine_strategy(Loop& L) { return std::make_unique<SineStrategy>(L.plan); }

}  // namespace hystlab::daemon
