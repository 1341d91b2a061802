#pragma once
// Builds an Everett table node by node while a campaign runs. Unmeasured nodes are filled so
// that their cells carry zero Preisach weight: the partial table is always a valid model.
#include <cstddef>
#include <system_error>
#include <vector>

#include "hystlab/models/everett_table.hpp"
#include "hystlab/models/fot_node.hpp"

namespace hystlab::models {

enum class FotError {
  off_grid_alpha = 1,
  off_grid_beta,
  beta_above_alpha,
  not_finite,
};
[[nodiscard]] const std::error_category& fot_error_category() noexcept;
[[nodiscard]] inline std::error_code make_error_code(FotError e) noexcept { return {static_cast<int>(e), fot_error_category()}; }

class OnlineTableBuilder {
 public:
  // tolerance: how far (mm) a measured α or β may sit from its grid node (default 1e-6 of the span).
  explicit OnlineTableBuilder(Grid grid, double tolerance = -1.0);

  // Adds one node; repeated nodes are averaged. Returns an error and changes nothing when the
  // node is not on the grid.
  std::error_code add(const FotNode& node) noexcept;
  void set_force_offset(double offset) noexcept { force_offset_ = offset; }

  [[nodiscard]] const Grid& grid() const noexcept { return grid_; }
  [[nodiscard]] bool identified(int i, int j) const noexcept;       // node (i, j); the diagonal is always known
  [[nodiscard]] bool cell_identified(int p, int q) const noexcept;  // all corners of cell (p, q) known
  [[nodiscard]] std::size_t identified_nodes() const noexcept;      // off-diagonal nodes measured
  [[nodiscard]] std::size_t required_nodes() const noexcept { return grid_.node_count() - static_cast<std::size_t>(grid_.n) - 1; }
  [[nodiscard]] bool complete() const noexcept { return identified_nodes() == required_nodes(); }
  // Per-node count of measurements (lower triangle order).
  [[nodiscard]] const std::vector<int>& counts() const noexcept { return count_; }

  // The builder of a coarser grid made of some of these nodes (indices into this grid, increasing,
  // from 0 to n): their measurements, sums and counts carried over (an adaptive campaign's table is
  // that of the rows it measured, each descent having passed every node of the fine grid below its
  // top). Throws std::invalid_argument for indices that are not such a subset.
  [[nodiscard]] OnlineTableBuilder restricted(const std::vector<int>& nodes) const;

  // The table so far: measured means, F(α,α) = 0, zero-weight fill elsewhere.
  [[nodiscard]] EverettTable table() const;

  // f_α per grid row i: every value seen, for the drift/repeatability figure.
  [[nodiscard]] const std::vector<std::vector<double>>& force_alpha_by_row() const noexcept { return f_alpha_; }

 private:
  Grid grid_;
  double tolerance_;
  double force_offset_ = 0.0;
  std::vector<double> sum_;
  std::vector<int> count_;
  std::vector<std::vector<double>> f_alpha_;
};

}  // namespace hystlab::models

template <>
struct std::is_error_code_enum<hystlab::models::FotError> : std::true_type {};
