#pragma once
// One interface for every rate-independent hysteresis model: driven one input at a time.
#include <cstdint>
#include <memory>
#include <span>

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

  // out[k] = step(in[k]); out must be at least as long as in.
  void evaluate(std::span<const double> in, std::span<double> out) noexcept {
    for (std::size_t k = 0; k < in.size(); ++k) out[k] = step(in[k]);
  }
};

}  // namespace hystlab::models
