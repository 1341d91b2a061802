#pragma once
// One interface for every rate-independent hysteresis model: driven one input at a time.
#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <vector>

namespace hystlab::models {

class HysteresisModel {
 public:
  virtual ~HysteresisModel() = default;
  // Back to the start state (virgin material / empty memory).
  virtual void reset() noexcept = 0;
  // Drive to displacement x (mm); returns the force (N).
  virtual double step(double x) noexcept = 0;
  // The force step(x) would return, without changing the state.
  [[nodiscard]] virtual double peek(double x) const noexcept = 0;
  [[nodiscard]] virtual std::unique_ptr<HysteresisModel> clone() const = 0;
  [[nodiscard]] virtual double input() const noexcept = 0;
  [[nodiscard]] virtual double output() const noexcept = 0;
  // Inputs that were clamped to the model's range (0 for models without one).
  [[nodiscard]] virtual std::uint64_t saturation_count() const noexcept { return 0; }

  // The state (the memory, the input and the counters) as numbers, to roll a simulation back or
  // store it: after restore_state(save_state()) every future output is the same to the last bit.
  // restore_state checks what it can (sizes, kinds, ranges, finiteness) and throws
  // std::invalid_argument naming what is wrong; it cannot tell two tables of one grid apart, so a
  // caller that stores states keeps the table's fingerprint beside them (the FMU does).
  [[nodiscard]] virtual std::vector<double> save_state() const { throw std::invalid_argument("this model's state cannot be saved"); }
  virtual void restore_state(std::span<const double> /*state*/) { throw std::invalid_argument("this model's state cannot be restored"); }

  // out[k] = step(in[k]); out must be at least as long as in.
  void evaluate(std::span<const double> in, std::span<double> out) noexcept {
    for (std::size_t k = 0; k < in.size(); ++k) out[k] = step(in[k]);
  }
};

}  // namespace hystlab::models
