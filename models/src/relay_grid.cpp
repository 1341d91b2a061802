#include "hystlab/models/relay_grid.hpp"

#include <stdexcept>

namespace hystlab::models {

RelayGrid::RelayGrid(std::vector<Relay> relays) : relays_(std::move(relays)), on_(relays_.size(), 0) {
  for (const Relay& r : relays_)
    if (!(r.beta <= r.alpha)) throw std::invalid_argument("relay grid: a relay has beta > alpha");
  reset();
}

void RelayGrid::reset() noexcept {
  std::fill(on_.begin(), on_.end(), std::uint8_t{0});
  x_ = 0.0;
  f_ = 0.0;
}

double RelayGrid::step(double x) noexcept {
  double f = 0.0;
  const std::size_t n = relays_.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Relay& r = relays_[k];
    std::uint8_t s = on_[k];
    if (x >= r.alpha)
      s = 1;
    else if (x <= r.beta)
      s = 0;
    on_[k] = s;
    f += s ? r.weight : 0.0;
  }
  x_ = x;
  f_ = f;
  return f;
}

double RelayGrid::peek(double x) const noexcept {
  RelayGrid copy(*this);
  return copy.step(x);
}

EverettTable RelayGrid::everett_table(const Grid& grid) const {
  std::vector<double> values(grid.node_count(), 0.0);
  for (int i = 0; i <= grid.n; ++i)
    for (int j = 0; j < i; ++j) {
      const double a = grid.node(i), b = grid.node(j);
      double sum = 0.0;
      for (const Relay& r : relays_)
        if (r.alpha <= a && r.beta >= b) sum += r.weight;
      values[Grid::index(i, j)] = sum;
    }
  return EverettTable(grid, std::move(values));
}

}  // namespace hystlab::models
