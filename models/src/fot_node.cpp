#include "hystlab/models/fot_node.hpp"

#include <cmath>
#include <stdexcept>

namespace hystlab::models {

std::vector<double> fot_turning_points(const Grid& grid) {
  std::vector<double> tp;
  tp.reserve(static_cast<std::size_t>(2 * grid.n + 1));
  tp.push_back(grid.lo);
  for (int i = 1; i <= grid.n; ++i) {
    tp.push_back(grid.node(i));
    tp.push_back(grid.lo);
  }
  return tp;
}

std::vector<double> ramp_through(const std::vector<double>& turning_points, double max_step) {
  if (!(max_step > 0.0) || !std::isfinite(max_step)) throw std::invalid_argument("ramp: step must be > 0");
  std::vector<double> out;
  if (turning_points.empty()) return out;
  out.push_back(turning_points.front());
  for (std::size_t k = 1; k < turning_points.size(); ++k) {
    const double a = turning_points[k - 1], b = turning_points[k];
    const auto steps = static_cast<std::size_t>(std::ceil(std::fabs(b - a) / max_step));
    for (std::size_t s = 1; s <= steps; ++s) out.push_back(s == steps ? b : a + (b - a) * static_cast<double>(s) / static_cast<double>(steps));
  }
  return out;
}

VirtualCampaign run_virtual_fot(HysteresisModel& model, const Grid& grid) {
  VirtualCampaign c;
  c.nodes.reserve(grid.node_count());
  model.reset();
  c.force_at_min = model.step(grid.lo);
  for (int i = 1; i <= grid.n; ++i) {
    for (int k = 1; k <= i; ++k) model.step(grid.node(k));  // rise through every node to δ_i
    const double f_alpha = model.output();
    for (int j = i - 1; j >= 0; --j) {  // descend, passing each δ_j
      const double f = model.step(grid.node(j));
      c.nodes.push_back(FotNode{grid.node(i), grid.node(j), f_alpha, f});
    }
  }
  return c;
}

}  // namespace hystlab::models
