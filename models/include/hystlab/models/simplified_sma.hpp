#pragma once
// The physically based simplified SMA model with continuous minor loops (docs/MODELS.md §2).
#include <memory>
#include <string>

#include "hystlab/models/hysteresis_model.hpp"

namespace hystlab::models {

// The fields of docs/examples/table1-params.json (docs/FORMATS.md). Stiffness N/mm, mm, N/°C, °C.
struct SmaParameters {
  double KA = 40.0, KM = 150.0, dtr_max = 2.95, C = 5.7;
  double Mf0 = 12.7, Ms0 = 17.9, As0 = 17.9, Af0 = 21.5, T = 25.0;
};

// The paper's Table 1.
[[nodiscard]] inline SmaParameters table1_parameters() { return SmaParameters{}; }

struct TransitionPoint {
  double displacement = 0.0;  // mm
  double force = 0.0;         // N
};

struct SmaTransitions {
  TransitionPoint Ms, Mf, As, Af;
  [[nodiscard]] double forward_slope() const { return (Mf.force - Ms.force) / (Mf.displacement - Ms.displacement); }
  [[nodiscard]] double reverse_slope() const { return (As.force - Af.force) / (As.displacement - Af.displacement); }
};

// Eqs. 10-18 with the erratum (δMf and δAs include + δtr_max).
[[nodiscard]] SmaTransitions transitions(const SmaParameters& p) noexcept;
// Throws std::invalid_argument naming the field that makes the model meaningless.
void validate(const SmaParameters& p);

class SimplifiedSmaModel final : public HysteresisModel {
 public:
  enum class Phase { Elastic, Forward, Reverse };

  explicit SimplifiedSmaModel(const SmaParameters& p);  // validates

  void reset() noexcept override;
  double step(double x) noexcept override;
  [[nodiscard]] double peek(double x) const noexcept override {
    SimplifiedSmaModel copy(*this);
    return copy.step(x);
  }
  [[nodiscard]] std::unique_ptr<HysteresisModel> clone() const override { return std::make_unique<SimplifiedSmaModel>(*this); }
  [[nodiscard]] double input() const noexcept override { return d_; }
  [[nodiscard]] double output() const noexcept override { return f_; }
  // [kind 2, phase, d, f, xi, anchor_d, anchor_f, k, entry_d, entry_xi].
  [[nodiscard]] std::vector<double> save_state() const override;
  void restore_state(std::span<const double> state) override;

  [[nodiscard]] double martensite_fraction() const noexcept { return xi_; }
  [[nodiscard]] Phase phase() const noexcept { return phase_; }
  [[nodiscard]] const SmaParameters& parameters() const noexcept { return p_; }
  [[nodiscard]] const SmaTransitions& transition_points() const noexcept { return tr_; }
  // Reuss stiffness of the elastic line at fraction xi (Eqs. 28, 34).
  [[nodiscard]] double elastic_stiffness(double xi) const noexcept { return p_.KA * p_.KM / (xi * (p_.KA - p_.KM) + p_.KM); }

 private:
  void enter_elastic(double anchor_d, double anchor_f, double xi) noexcept;
  void enter_transformation(Phase phase, double d) noexcept;
  [[nodiscard]] double forward_meet() const noexcept;  // where loading on the elastic line meets the forward line
  [[nodiscard]] double reverse_meet() const noexcept;  // where unloading meets the reverse line
  [[nodiscard]] double forward_force(double d) const noexcept { return tr_.Ms.force + tr_.forward_slope() * (d - tr_.Ms.displacement); }
  [[nodiscard]] double reverse_force(double d) const noexcept { return tr_.Af.force + tr_.reverse_slope() * (d - tr_.Af.displacement); }
  bool advance_elastic(double x) noexcept;  // true when x is reached
  bool advance_forward(double x) noexcept;
  bool advance_reverse(double x) noexcept;

  SmaParameters p_;
  SmaTransitions tr_;
  Phase phase_ = Phase::Elastic;
  double d_ = 0.0, f_ = 0.0, xi_ = 0.0;
  double anchor_d_ = 0.0, anchor_f_ = 0.0, k_ = 0.0;  // elastic line
  double entry_d_ = 0.0, entry_xi_ = 0.0;             // transformation segment
};

}  // namespace hystlab::models
