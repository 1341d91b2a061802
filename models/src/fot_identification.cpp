#include "hystlab/models/fot_identification.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace hystlab::models {
namespace {
std::string describe(const FotNode& n) {
  std::ostringstream s;
  s << "node (alpha " << n.alpha << " mm, beta " << n.beta << " mm)";
  return s.str();
}
}  // namespace

std::vector<CellWeight> cell_weights(const EverettTable& t) {
  std::vector<CellWeight> w;
  const int n = t.grid().n;
  w.reserve(t.grid().cell_count());
  for (int p = 1; p <= n; ++p)
    for (int q = 1; q <= p; ++q) {
      const double m = q == p ? t.node_value(p, p - 1) : t.node_value(p, q - 1) - t.node_value(p, q) - t.node_value(p - 1, q - 1) + t.node_value(p - 1, q);
      w.push_back(CellWeight{p, q, m});
    }
  return w;
}

DriftReport drift_report(const OnlineTableBuilder& builder) {
  DriftReport r;
  double ss = 0.0;
  std::size_t dof = 0;
  const auto& rows = builder.force_alpha_by_row();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& v = rows[i];
    if (v.size() < 2) continue;
    ++r.repeated_rows;
    const auto [mn, mx] = std::minmax_element(v.begin(), v.end());
    if (*mx - *mn > r.max_spread) {
      r.max_spread = *mx - *mn;
      r.worst_row = static_cast<int>(i);
    }
    double mean = 0.0;
    for (double x : v) mean += x;
    mean /= static_cast<double>(v.size());
    for (double x : v) ss += (x - mean) * (x - mean);
    dof += v.size() - 1;
  }
  r.pooled_std = dof > 0 ? std::sqrt(ss / static_cast<double>(dof)) : 0.0;
  return r;
}

std::vector<CellWeight> monotonicity_violations(const EverettTable& table, double threshold) {
  std::vector<CellWeight> out;
  for (const CellWeight& c : cell_weights(table))
    if (c.weight < -threshold) out.push_back(c);
  return out;
}

Grid infer_grid(const std::vector<FotNode>& nodes) {
  if (nodes.empty()) throw std::invalid_argument("FOT data: no nodes");
  double lo = nodes.front().beta, hi = nodes.front().alpha;
  for (const FotNode& n : nodes) {
    if (!std::isfinite(n.alpha) || !std::isfinite(n.beta)) throw std::invalid_argument("FOT data: " + describe(n) + " is not finite");
    if (n.beta > n.alpha) throw std::invalid_argument("FOT data: " + describe(n) + " has beta above alpha");
    lo = std::min(lo, n.beta);
    hi = std::max(hi, n.alpha);
  }
  if (!(hi > lo)) throw std::invalid_argument("FOT data: all alpha and beta values are equal");
  const double tol = 1e-6 * (hi - lo);
  std::vector<double> alphas;
  for (const FotNode& n : nodes)
    if (n.alpha > lo + tol) alphas.push_back(n.alpha);
  std::sort(alphas.begin(), alphas.end());
  std::vector<double> distinct;
  for (double a : alphas)
    if (distinct.empty() || a - distinct.back() > tol) distinct.push_back(a);
  // The distinct α values are the grid's nodes above δmin: uniform when they are (within 1e-6 of
  // the range), else a grid of its own (table format version 2). The β values must lie on the same
  // nodes (the builder refuses any other).
  const Grid u = Grid::make(lo, hi, static_cast<int>(distinct.size()));
  bool uniform = true;
  for (std::size_t k = 0; k < distinct.size() && uniform; ++k) uniform = std::fabs(distinct[k] - u.node(static_cast<int>(k) + 1)) <= tol;
  if (uniform) return u;
  std::vector<double> x{lo};
  x.insert(x.end(), distinct.begin(), distinct.end());
  x.back() = hi;
  return Grid::from_nodes(x);
}

FotIdentification identify_from_nodes(const std::vector<FotNode>& nodes, double noise_std, double force_offset) {
  return identify_from_nodes(infer_grid(nodes), nodes, noise_std, force_offset);
}

FotIdentification identify_from_nodes(const Grid& grid, const std::vector<FotNode>& nodes, double noise_std, double force_offset) {
  OnlineTableBuilder builder(grid);
  builder.set_force_offset(force_offset);
  for (const FotNode& n : nodes)
    if (const std::error_code ec = builder.add(n)) throw std::invalid_argument("FOT data: " + describe(n) + ": " + ec.message());
  for (int i = 1; i <= grid.n; ++i)
    for (int j = 0; j < i; ++j)
      if (!builder.identified(i, j)) throw std::invalid_argument("FOT data: missing " + describe(FotNode{grid.node(i), grid.node(j), 0, 0}));
  FotIdentification r{builder.table(), drift_report(builder), 0.0, {}, nodes.size()};
  double scale = 0.0;
  for (double v : r.table.values()) scale = std::max(scale, std::fabs(v));
  const double sigma = noise_std >= 0.0 ? noise_std : r.drift.pooled_std;
  // A cell weight is a four-term difference of F values, each f_α - f_αβ: its noise is √8 σ.
  r.violation_threshold = 3.0 * std::sqrt(8.0) * sigma + 1e-9 * scale;
  r.violations = monotonicity_violations(r.table, r.violation_threshold);
  return r;
}

EverettTable identify_virtual(HysteresisModel& model, const Grid& grid) {
  const VirtualCampaign c = run_virtual_fot(model, grid);
  return identify_from_nodes(grid, c.nodes, 0.0, c.force_at_min).table;
}

}  // namespace hystlab::models
