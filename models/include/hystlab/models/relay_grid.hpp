#pragma once
// Brute-force Preisach model: every relay H(α,β) is stored and switched on each step.
// O(relays) per step; the reference that the Everett evaluation is checked and benchmarked against.
#include <cstdint>
#include <memory>
#include <vector>

#include "hystlab/models/everett_table.hpp"
#include "hystlab/models/hysteresis_model.hpp"

namespace hystlab::models {

struct Relay {
  double alpha = 0.0;  // switches on when x >= alpha
  double beta = 0.0;   // switches off when x <= beta (beta <= alpha)
  double weight = 0.0;
};

class RelayGrid final : public HysteresisModel {
 public:
  // All relays start off (the state at δmin below every threshold).
  explicit RelayGrid(std::vector<Relay> relays);

  void reset() noexcept override;
  double step(double x) noexcept override;
  [[nodiscard]] double peek(double x) const noexcept override;
  [[nodiscard]] std::unique_ptr<HysteresisModel> clone() const override { return std::make_unique<RelayGrid>(*this); }
  [[nodiscard]] double input() const noexcept override { return x_; }
  [[nodiscard]] double output() const noexcept override { return f_; }
  [[nodiscard]] const std::vector<Relay>& relays() const noexcept { return relays_; }

  // F(δ_i, δ_j) computed exactly from the relays: the weight of those with α <= δ_i and β >= δ_j.
  [[nodiscard]] EverettTable everett_table(const Grid& grid) const;

 private:
  std::vector<Relay> relays_;
  std::vector<std::uint8_t> on_;
  double x_ = 0.0;
  double f_ = 0.0;
};

}  // namespace hystlab::models
