#pragma once
// A superelastic specimen that has not been trained (hystlab-sim --shakedown EXTRA,TAU): its
// forward transformation (the upper plateau, Ms and Mf) starts EXTRA newtons higher and comes down
// by exp(-N/TAU) with every transformation cycle N, as a NiTi spring's upper plateau drops over
// its first tens of cycles and settles (the reverse plateau moves far less, so the loop narrows
// and its dissipated energy settles with it). A cycle is counted when the specimen, having
// transformed (martensite fraction above 1/2), is back to austenite (fraction 0, elastic): there
// its next cycle's parameters take over, on the same austenite line, so the force is continuous.
#include "hystlab/models/simplified_sma.hpp"

namespace hystlab::sim {

class ShakedownSpecimen final : public models::HysteresisModel {
 public:
  ShakedownSpecimen(const models::SmaParameters& settled, double extra_N, double tau_cycles);

  void reset() noexcept override;
  double step(double x) noexcept override;
  [[nodiscard]] double peek(double x) const noexcept override { return model_.peek(x); }
  [[nodiscard]] std::unique_ptr<models::HysteresisModel> clone() const override { return std::make_unique<ShakedownSpecimen>(*this); }
  [[nodiscard]] double input() const noexcept override { return model_.input(); }
  [[nodiscard]] double output() const noexcept override { return model_.output(); }
  [[nodiscard]] int cycles() const noexcept { return cycles_; }
  // The parameters of cycle n (0: the first).
  [[nodiscard]] models::SmaParameters parameters_of(int n) const noexcept;

 private:
  models::SmaParameters settled_;
  double extra_, tau_;
  int cycles_ = 0;
  bool transformed_ = false;
  models::SimplifiedSmaModel model_;
};

}  // namespace hystlab::sim
