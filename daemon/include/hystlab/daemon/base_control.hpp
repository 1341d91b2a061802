#pragma once
// Closed-loop base amplitude (pure: measured amplitudes in, the next drive out), as a sine
// controller holds it: the drive is corrected after every window towards the demand (the error
// converges to 0; the tolerance, warning and abort bands are alarms, not where correction stops).
// The table's response per unit of drive (base/drive) changes with frequency and with the load,
// so it is learnt at each frequency as the sweep goes, and a step starts at the drive that the
// response learnt there (interpolated between the nearest frequencies learnt) asks for: the
// excitation is carried across steps, never dropped.
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "hystlab/domain/sine_plan.hpp"

namespace hystlab::daemon {

enum class ControlBand : std::uint8_t { within, outside, warning, abort };  // |error| ≤ tolerance < … ≤ warning < … ≤ abort < …
[[nodiscard]] const char* to_string(ControlBand b) noexcept;

struct ControlVerdict {
  double error_pct = 0;  // (measured − demand) / demand
  ControlBand band = ControlBand::within;
  bool converged = false;  // |error| ≤ control.converge: the step may settle and be measured
  double next_drive_mm = 0;
  bool limited = false;  // the drive wanted more than max_drive_ratio × demand
};

class BaseControl {
 public:
  explicit BaseControl(const domain::SineControl& c) noexcept : c_(c) {}
  // The drive to start a step at f: the demand over the response learnt at f; before anything is
  // learnt, start_level × the demand (the campaign's first step, from below). Open loop: the demand.
  [[nodiscard]] double start(double f_hz, double demand_mm) const noexcept;
  // A window at f measured at `drive` gave `measured`: its band, and the drive for the next window
  // (corrected by gain × the error whatever the band; open loop: unchanged).
  ControlVerdict update(double f_hz, double demand_mm, double drive_mm, double measured_mm) noexcept;
  [[nodiscard]] ControlBand band_of(double error_pct) const noexcept;
  // Base per unit of drive at f: interpolated in log frequency between the nearest frequencies
  // learnt, the nearest one's beyond them; 1 before anything is learnt.
  [[nodiscard]] double response_at(double f_hz) const noexcept;

 private:
  void learn(double f_hz, double response) noexcept;
  domain::SineControl c_;
  // The frequencies learnt, ascending, at most kLearnt (a continuous sweep's windows within 1 %
  // of a frequency learnt replace it): fixed storage, no allocation on the acquisition thread.
  static constexpr std::size_t kLearnt = 256;
  std::array<std::pair<double, double>, kLearnt> learnt_{};
  std::size_t n_ = 0;
};

}  // namespace hystlab::daemon
