#pragma once
// A linear spring, F = k·δ: the reference the SMA isolator is compared with, and the case the
// SDOF integrator is checked on against the analytic solution.
#include <memory>
#include <stdexcept>

#include "hystlab/models/hysteresis_model.hpp"

namespace hystlab::models {

class LinearSpring final : public HysteresisModel {
 public:
  explicit LinearSpring(double stiffness_N_per_mm) : k_(stiffness_N_per_mm) {
    if (!(k_ > 0) || k_ > 1e12) throw std::invalid_argument("linear spring: the stiffness must be a positive number of N/mm");
  }
  void reset() noexcept override { x_ = f_ = 0; }
  double step(double x) noexcept override {
    x_ = x;
    return f_ = k_ * x;
  }
  [[nodiscard]] double peek(double x) const noexcept override { return k_ * x; }
  [[nodiscard]] std::unique_ptr<HysteresisModel> clone() const override { return std::make_unique<LinearSpring>(*this); }
  [[nodiscard]] double input() const noexcept override { return x_; }
  [[nodiscard]] double output() const noexcept override { return f_; }
  [[nodiscard]] double stiffness() const noexcept { return k_; }

 private:
  double k_, x_ = 0, f_ = 0;
};

}  // namespace hystlab::models
