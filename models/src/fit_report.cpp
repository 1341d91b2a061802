#include "hystlab/models/fit_report.hpp"

namespace hystlab::models {

nlohmann::json fit_provenance(const PreisachFitResult& r) {
  const PriorFit& c = r.chosen;
  nlohmann::json candidates = nlohmann::json::array();
  for (const PriorFit& f : r.candidates)
    candidates.push_back({{"prior", to_string(f.prior)},
                          {"lambda", f.lambda},
                          {"heldout_rms_N", f.heldout_rms},
                          {"rms_residual_N", f.rms_residual},
                          {"cv", {{"lambda", f.cv_lambda}, {"heldout_rms_N", f.cv_rms}}}});
  return {{"prior", to_string(c.prior)},
          {"reason", r.reason},
          {"lambda", c.lambda},
          {"heldout_rms_N", c.heldout_rms},
          {"rms_residual_N", c.rms_residual},
          {"max_residual_N", c.max_residual},
          {"converged", c.converged},
          {"negative_cells", c.negative_cells},
          {"cells_at_bound", c.cells_at_bound},
          {"cell_sigma_N", c.cell_sigma},
          {"candidates", candidates},
          {"seconds", r.seconds},
          {"peak_bytes", r.peak_bytes},
          {"selection_samples", r.selection_samples}};
}

}  // namespace hystlab::models
