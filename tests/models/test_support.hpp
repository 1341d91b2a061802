#pragma once
// Shared generators for the model tests: seeded, so a failing case can be replayed.
#include <random>
#include <vector>

#include "hystlab/models/grid.hpp"
#include "hystlab/models/hysteresis_model.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/relay_grid.hpp"

namespace hystlab::test {

// A random walk of turning points in [lo, hi], ramped with the given step.
inline std::vector<double> random_ramps(std::mt19937_64& rng, double lo, double hi, int reversals, double step) {
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> out{lo};
  double x = lo;
  for (int r = 0; r < reversals; ++r) {
    const double target = u(rng);
    const int n = std::max(1, static_cast<int>(std::abs(target - x) / step));
    for (int k = 1; k <= n; ++k) out.push_back(x + (target - x) * k / n);
    x = target;
  }
  return out;
}

// Inputs drawn from the grid nodes only (where the interpolated table is exact).
inline std::vector<double> random_node_inputs(std::mt19937_64& rng, const models::Grid& g, int count) {
  std::uniform_int_distribution<int> pick(0, g.n);
  std::vector<double> out;
  for (int k = 0; k < count; ++k) out.push_back(g.node(pick(rng)));
  return out;
}

// Relays strictly between grid nodes (one per cell, at a random place inside it) with random weights.
inline std::vector<models::Relay> random_relays(std::mt19937_64& rng, const models::Grid& g) {
  std::uniform_real_distribution<double> frac(0.05, 0.95), weight(0.1, 1.1);
  std::vector<models::Relay> relays;
  for (int p = 1; p <= g.n; ++p)
    for (int q = 1; q <= p; ++q) {
      double a = g.node(p - 1) + frac(rng) * g.step();
      double b = g.node(q - 1) + frac(rng) * g.step();
      if (q == p && b > a) std::swap(a, b);
      relays.push_back(models::Relay{a, b, weight(rng)});
    }
  return relays;
}

// The model's output for an input record, from its present state.
inline std::vector<double> run_model(models::HysteresisModel& m, const std::vector<double>& in) {
  std::vector<double> out(in.size());
  m.evaluate(in, out);
  return out;
}

// A record of a table of random non-negative masses (random_relays) on random ramps over 0..4 mm
// with Gaussian force noise: what a fit with the monotone prior must recover.
struct RelayRecord {
  models::EverettTable truth;
  std::vector<double> x, y;
};
inline RelayRecord noisy_relay_record(std::mt19937_64& rng, const models::Grid& g, double sigma) {
  RelayRecord r{models::RelayGrid(random_relays(rng, g)).everett_table(g), {}, {}};
  models::PreisachModel gen(r.truth);
  r.x = random_ramps(rng, 0.0, 4.0, 120, 0.02);
  r.y = run_model(gen, r.x);
  std::normal_distribution<double> noise(0.0, sigma);
  for (double& v : r.y) v += noise(rng);
  return r;
}

}  // namespace hystlab::test
