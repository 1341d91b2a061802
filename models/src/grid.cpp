#include "hystlab/models/grid.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hystlab::models {

Grid Grid::make(double lo, double hi, int n) {
  if (!std::isfinite(lo)) throw std::invalid_argument("grid: range start is not a finite number");
  if (!std::isfinite(hi)) throw std::invalid_argument("grid: range end is not a finite number");
  if (!(hi > lo)) throw std::invalid_argument("grid: range end (" + std::to_string(hi) + ") must be greater than its start (" + std::to_string(lo) + ")");
  if (n < 1 || n > 2000) throw std::invalid_argument("grid: subdivisions must be between 1 and 2000, got " + std::to_string(n));
  return Grid{lo, hi, n, nullptr};
}

Grid Grid::from_nodes(const std::vector<double>& nodes) {
  if (nodes.size() < 2 || nodes.size() > 2001) throw std::invalid_argument("grid: nodes must number 2 to 2001, got " + std::to_string(nodes.size()));
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (!std::isfinite(nodes[i])) throw std::invalid_argument("grid: node " + std::to_string(i) + " is not a finite number");
    if (i > 0 && !(nodes[i] > nodes[i - 1]))
      throw std::invalid_argument("grid: node " + std::to_string(i) + " (" + std::to_string(nodes[i]) + ") is not above node " + std::to_string(i - 1) + " (" +
                                  std::to_string(nodes[i - 1]) + ")");
  }
  Grid g = make(nodes.front(), nodes.back(), static_cast<int>(nodes.size()) - 1);
  bool uniform = true;
  for (std::size_t i = 0; i < nodes.size() && uniform; ++i) uniform = std::fabs(nodes[i] - g.node(static_cast<int>(i))) <= 1e-12 * (g.hi - g.lo);
  if (!uniform) g.positions = std::make_shared<const std::vector<double>>(nodes);
  return g;
}

Grid Grid::refined(double lo, double hi, int n, double center, double width, double share) {
  const Grid u = make(lo, hi, n);
  if (!std::isfinite(center) || !(width > 0) || !std::isfinite(width))
    throw std::invalid_argument("grid: the refined window needs a finite centre and a width > 0");
  if (!(share > 0 && share < 1)) throw std::invalid_argument("grid: the refined share must be between 0 and 1");
  const double a = std::max(lo, center - width / 2), b = std::min(hi, center + width / 2);
  if (!(b > a)) throw std::invalid_argument("grid: the refined window lies outside the range");
  const double left = a - lo, right = hi - b, outside = left + right;
  int inner = std::clamp(static_cast<int>(std::lround(share * n)), 1, n);
  int nl = outside > 0 ? static_cast<int>(std::lround((n - inner) * left / outside)) : 0;
  int nr = n - inner - nl;
  // A side of the range with length gets a cell at least; the window gives them up.
  if (left > 0 && nl == 0) ++nl, --inner;
  if (right > 0 && nr == 0) ++nr, --inner;
  if (inner < 1) throw std::invalid_argument("grid: too few subdivisions to refine a window and keep both sides");
  std::vector<double> x{lo};
  for (int k = 1; k <= nl; ++k) x.push_back(lo + left * k / nl);
  for (int k = 1; k <= inner; ++k) x.push_back(a + (b - a) * k / inner);
  for (int k = 1; k <= nr; ++k) x.push_back(b + right * k / nr);
  x.back() = hi;
  return from_nodes(x);
}

double Grid::step() const noexcept {
  if (!positions) return (hi - lo) / n;
  double s = hi - lo;
  for (std::size_t i = 1; i < positions->size(); ++i) s = std::min(s, (*positions)[i] - (*positions)[i - 1]);
  return s;
}

int Grid::cell_of(double x, double& fraction) const noexcept {
  x = x < lo ? lo : (x > hi ? hi : x);
  if (!positions) {
    const double u = (x - lo) / (hi - lo) * n;
    int i = static_cast<int>(u) + 1;
    i = i > n ? n : i;
    fraction = u - static_cast<double>(i - 1);
    return i;
  }
  return cell_among(positions->data(), n, x, fraction);
}

std::vector<double> Grid::nodes() const {
  std::vector<double> out;
  for (int i = 0; i <= n; ++i) out.push_back(node(i));
  return out;
}

int Grid::node_near(double x, double tol) const noexcept {
  if (!std::isfinite(x)) return -1;
  int i = 0;
  if (!positions) {
    const double r = std::round((x - lo) / (hi - lo) * n);
    if (r < 0.0 || r > static_cast<double>(n)) return -1;
    i = static_cast<int>(r);
  } else {
    const auto& p = *positions;
    const auto it = std::lower_bound(p.begin(), p.end(), x);
    const int k = static_cast<int>(it - p.begin());
    i = k >= static_cast<int>(p.size()) ? n : k;
    if (k > 0 && (k > n || std::fabs(x - p[static_cast<std::size_t>(k - 1)]) < std::fabs(p[static_cast<std::size_t>(i)] - x))) i = k - 1;
  }
  return std::fabs(x - node(i)) <= tol ? i : -1;
}

bool Grid::same_nodes(const Grid& o, double tol) const noexcept {
  if (n != o.n) return false;
  for (int i = 0; i <= n; ++i)
    if (std::fabs(node(i) - o.node(i)) > tol) return false;
  return true;
}

}  // namespace hystlab::models
