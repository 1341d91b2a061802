#pragma once
// Identification of an Everett table from measured FOT nodes, with the figures a lab needs
// to trust it: repeatability of f_α and cells whose Preisach weight is negative beyond noise.
#include <cstddef>
#include <vector>

#include "hystlab/models/everett_table.hpp"
#include "hystlab/models/fot_node.hpp"
#include "hystlab/models/online_table_builder.hpp"

namespace hystlab::models {

struct DriftReport {
  double max_spread = 0.0;  // N, largest max-min of f_α at one α
  double pooled_std = 0.0;  // N, pooled standard deviation of repeated f_α (0 without repeats)
  int worst_row = 0;        // grid row i of max_spread
  std::size_t repeated_rows = 0;
};

struct CellWeight {
  int p = 0, q = 0;     // cell (p, q): α in [δ_{p-1}, δ_p], β in [δ_{q-1}, δ_q]
  double weight = 0.0;  // N, the Preisach mass of the cell
};

struct FotIdentification {
  EverettTable table;
  DriftReport drift;
  double violation_threshold = 0.0;    // N: a cell weight below -threshold is reported
  std::vector<CellWeight> violations;  // monotonicity violations beyond noise
  std::size_t node_count = 0;
};

// Cell weights (Preisach masses) of a table; rectangles by inclusion-exclusion, triangles F(δ_p, δ_{p-1}).
[[nodiscard]] std::vector<CellWeight> cell_weights(const EverettTable& table);

[[nodiscard]] DriftReport drift_report(const OnlineTableBuilder& builder);
// noise_std: the force noise (N) to judge violations; < 0 means use the drift figure.
[[nodiscard]] std::vector<CellWeight> monotonicity_violations(const EverettTable& table, double threshold);

// Infers the grid from the nodes (α values δ1..δn, β down to δmin) unless one is given.
// Throws std::invalid_argument naming the node or value when the nodes do not form a complete
// uniform grid.
[[nodiscard]] Grid infer_grid(const std::vector<FotNode>& nodes);
[[nodiscard]] FotIdentification identify_from_nodes(const std::vector<FotNode>& nodes, double noise_std = -1.0, double force_offset = 0.0);
[[nodiscard]] FotIdentification identify_from_nodes(const Grid& grid, const std::vector<FotNode>& nodes, double noise_std = -1.0, double force_offset = 0.0);

// MODELS.md §3: the table of a model, from its response to the identification input.
[[nodiscard]] EverettTable identify_virtual(HysteresisModel& model, const Grid& grid);

}  // namespace hystlab::models
