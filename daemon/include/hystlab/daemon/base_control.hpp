#pragma once
// Closed-loop base amplitude (pure: measured amplitudes in, the next drive out). A sine
// controller holds the measured base amplitude at the demand by correcting the drive after each
// window; the table's response per unit of drive (here: base/drive) changes with frequency and
// with the load, so it is learnt as it goes, and a new step starts from the last one learnt.
#include <cstdint>

#include "hystlab/domain/sine_plan.hpp"

namespace hystlab::daemon {

enum class ControlBand : std::uint8_t { within, outside, warning, abort };  // |error| ≤ tolerance < … ≤ warning < … ≤ abort < …
[[nodiscard]] const char* to_string(ControlBand b) noexcept;

struct ControlVerdict {
  double error_pct = 0;  // (measured − demand) / demand
  ControlBand band = ControlBand::within;
  double next_drive_mm = 0;
  bool limited = false;  // the drive wanted more than max_drive_ratio × demand
};

class BaseControl {
 public:
  explicit BaseControl(const domain::SineControl& c) noexcept : c_(c) {}
  // The drive to start a step at: start_level × the demand over the response last learnt (open loop: the demand).
  [[nodiscard]] double start(double demand_mm) const noexcept;
  // A window measured at `drive` gave `measured`: its band and the drive for the next window.
  ControlVerdict update(double demand_mm, double drive_mm, double measured_mm) noexcept;
  [[nodiscard]] ControlBand band_of(double error_pct) const noexcept;
  [[nodiscard]] double response() const noexcept { return response_; }  // base per unit of drive

 private:
  domain::SineControl c_;
  double response_ = 1.0;
};

}  // namespace hystlab::daemon
