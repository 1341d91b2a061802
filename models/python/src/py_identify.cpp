// Identification, fits and calibration as `hystlab identify | fit | calibrate` do them (the same
// option rules and provenance, daemon/cli/cmd_identify.cpp), and the accuracy and loop measures.
// Numbers only come from hystlab::models; this file turns arguments into its calls.
#include <algorithm>
#include <cmath>
#include <optional>

#include "bindings.hpp"
#include "hystlab/models/accuracy.hpp"
#include "hystlab/models/fit_report.hpp"
#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/loop_figures.hpp"
#include "hystlab/models/loop_report.hpp"
#include "hystlab/models/preisach_fit.hpp"
#include "hystlab/models/sma_calibration.hpp"
#include "hystlab/models/table_score.hpp"

namespace hystlab::python {
namespace {

using OptRange = std::optional<std::pair<double, double>>;
using OptNumbers = std::optional<std::vector<double>>;

std::pair<double, double> checked_range(const std::pair<double, double>& r) {
  if (!std::isfinite(r.first) || !std::isfinite(r.second)) throw std::invalid_argument("range: not a finite number");
  if (!(r.second > r.first)) throw std::invalid_argument("range: the end must be greater than the start");
  return r;
}

int checked_subdivisions(const std::optional<int>& n, int hi) {
  if (!n) throw std::invalid_argument("subdivisions is required (or nodes)");
  if (*n < 1 || *n > hi) throw std::invalid_argument("subdivisions: must be a whole number from 1 to " + std::to_string(hi) + ", got " + std::to_string(*n));
  return *n;
}

models::Grid refine(double lo, double hi, int n, const std::vector<double>& r) {
  if (r.size() != 2 && r.size() != 3) throw std::invalid_argument("refine: expected (center, width) or (center, width, share)");
  return models::Grid::refined(lo, hi, n, r[0], r[1], r.size() == 3 ? r[2] : 0.5);
}

// The grid of identify: nodes, or range and subdivisions, optionally refined (grid_option of the CLI).
models::Grid grid_of(const OptRange& range, const std::optional<int>& n, const OptNumbers& refinement, const OptNumbers& nodes, int max_n) {
  if (nodes) {
    if (range || n || refinement) throw std::invalid_argument("nodes gives the whole grid: leave out range, subdivisions and refine");
    models::Grid g = models::Grid::from_nodes(*nodes);
    if (g.n > max_n) throw std::invalid_argument("nodes: at most " + std::to_string(max_n + 1) + " nodes");
    return g;
  }
  if (!range) throw std::invalid_argument("range is required (or nodes)");
  const auto [lo, hi] = checked_range(*range);
  const int sub = checked_subdivisions(n, max_n);
  return refinement ? refine(lo, hi, sub, *refinement) : models::Grid::make(lo, hi, sub);
}

Table identify_virtual(const Params& p, const OptRange& range, const std::optional<int>& n, const OptNumbers& refinement, const OptNumbers& nodes) {
  const models::Grid g = grid_of(range, n, refinement, nodes, 2000);
  models::TableProvenance prov;
  prov.created = now_iso8601();
  prov.method = "virtual-fot";
  models::SimplifiedSmaModel model(p.p);
  prov.source = "simplified SMA model" + (p.source.empty() ? std::string() : ", parameters " + p.source);
  prov.from = p.source.empty() ? "hystlab Python module" : p.source;
  prov.temperature_C = p.p.T;  // as hystlab identify --model simplified writes it
  models::EverettTable t;
  {
    py::gil_scoped_release release;
    t = models::identify_virtual(model, g);
  }
  return make_table(std::move(t), std::move(prov));
}

py::object identify_from_nodes(const py::handle& alpha, const py::handle& beta, const py::handle& fa, const py::handle& fab, std::optional<double> noise,
                               const std::string& origin, bool details) {
  const auto a = finite_vector(alpha, "alpha_mm"), b = finite_vector(beta, "beta_mm");
  const auto f1 = finite_vector(fa, "force_alpha_N"), f2 = finite_vector(fab, "force_alpha_beta_N");
  if (b.size() != a.size() || f1.size() != a.size() || f2.size() != a.size())
    throw std::invalid_argument("alpha_mm, beta_mm, force_alpha_N and force_alpha_beta_N must have the same length");
  if (a.empty()) throw std::invalid_argument("no nodes");
  if (noise && !(*noise >= 0)) throw std::invalid_argument("noise: must be >= 0");
  std::vector<models::FotNode> fot;
  for (std::size_t k = 0; k < a.size(); ++k) fot.push_back(models::FotNode{a[k], b[k], f1[k], f2[k]});
  const models::FotIdentification id = models::identify_from_nodes(fot, noise.value_or(-1.0));
  models::TableProvenance prov{"measured FOT nodes", "fot", now_iso8601(), origin, nlohmann::json::object()};
  prov.extra = {
      {"nodes", id.node_count}, {"drift_max_spread_N", id.drift.max_spread}, {"drift_pooled_std_N", id.drift.pooled_std}, {"violations", id.violations.size()}};
  Table table = make_table(id.table, std::move(prov));
  if (!details) return py::cast(table);
  py::list violations;
  for (const auto& c : id.violations) violations.append(py::make_tuple(c.p, c.q, c.weight));
  py::dict d;
  d["nodes"] = id.node_count;
  d["drift"] = py::dict(py::arg("max_spread_N") = id.drift.max_spread, py::arg("pooled_std_N") = id.drift.pooled_std, py::arg("worst_row") = id.drift.worst_row,
                        py::arg("repeated_rows") = id.drift.repeated_rows);
  d["violation_threshold_N"] = id.violation_threshold;
  d["violations"] = violations;
  return py::make_tuple(table, d);
}

Table fit(const py::handle& x, const py::handle& f, const std::optional<int>& n, const OptRange& range, const OptNumbers& refinement, const OptNumbers& nodes,
          const std::string& prior, std::optional<double> lambda, int folds, const std::string& origin) {
  const auto xv = finite_vector(x, "x"), fv = finite_vector(f, "f");
  models::PreisachFitOptions fo;
  models::Grid grid;
  if (nodes) {
    grid = grid_of(std::nullopt, std::nullopt, std::nullopt, nodes, fo.max_subdivisions);
    if (range || n || refinement) throw std::invalid_argument("nodes gives the whole grid: leave out range, subdivisions and refine");
  } else {
    const int sub = checked_subdivisions(n, fo.max_subdivisions);
    if (xv.empty()) throw std::invalid_argument("x: no samples");
    auto [lo, hi] = range ? checked_range(*range) : std::pair{*std::min_element(xv.begin(), xv.end()), *std::max_element(xv.begin(), xv.end())};
    if (!(hi > lo)) throw std::invalid_argument("x: the displacement never changes");
    grid = refinement ? refine(lo, hi, sub, *refinement) : models::Grid::make(lo, hi, sub);
  }
  if (lambda && !(*lambda >= 0)) throw std::invalid_argument("lambda_: must be >= 0");
  if (folds < 2 || folds > 20) throw std::invalid_argument("folds: must be a whole number from 2 to 20, got " + std::to_string(folds));
  fo.lambda = lambda.value_or(-1.0);
  fo.folds = folds;
  fo.prior = models::fit_prior_from_string(prior);
  std::optional<models::PreisachFitResult> r;
  {
    py::gil_scoped_release release;
    r = models::fit_preisach(xv, fv, grid, fo);
  }
  return make_table(r->chosen.table, {"displacement/force record", "lsq", now_iso8601(), origin, models::fit_provenance(*r)});
}

py::object calibrate(const py::handle& x, const py::handle& f, const std::optional<Params>& initial, std::optional<double> temperature,
                     std::optional<double> clausius, const std::string& origin, bool details) {
  models::SmaCalibrationOptions co;
  if (initial) {
    co.C = initial->p.C;
    co.T = initial->p.T;
  } else if (!temperature || !clausius) {
    throw std::invalid_argument("calibrate needs initial parameters, or both temperature and clausius");
  }
  co.T = temperature.value_or(co.T);
  co.C = clausius.value_or(co.C);
  if (!std::isfinite(co.T)) throw std::invalid_argument("temperature: not a finite number");
  if (!(co.C > 0) || !std::isfinite(co.C)) throw std::invalid_argument("clausius: must be > 0");
  const auto xv = finite_vector(x, "x"), fv = finite_vector(f, "f");
  std::optional<models::SmaCalibration> c;
  {
    py::gil_scoped_release release;
    c = models::calibrate_simplified_sma(xv, fv, co);
  }
  Params p{c->parameters, "calibrated from " + origin};
  if (!details) return py::cast(p);
  py::dict d;
  d["transitions"] = transitions_to_dict(c->transitions);
  d["initial_guess"] = Params{c->initial_guess, "initial guess"};
  d["rms_residual_N"] = c->rms_residual;
  d["max_residual_N"] = c->max_residual;
  d["iterations"] = c->iterations;
  return py::make_tuple(p, d);
}

py::object compare(const py::handle& x, const py::handle& ref, const py::handle& model) {
  const auto xv = finite_vector(x, "x"), rv = finite_vector(ref, "reference"), mv = finite_vector(model, "model");
  const models::AccuracyReport r = models::compare(xv, rv, mv);
  nlohmann::json j = models::accuracy_json(r);
  if (r.energy_reference) {
    j["loop_energy_reference_Nmm"] = *r.energy_reference;
    j["loop_energy_model_Nmm"] = *r.energy_model;
  }
  return json_to_py(j);
}

py::object loops(const py::handle& x, const py::handle& f, const std::vector<double>& plateaus, double reversal_fraction, double min_span_fraction) {
  const auto xv = finite_vector(x, "x"), fv = finite_vector(f, "f");
  models::LoopOptions lo;
  lo.plateau_at_mm = plateaus;
  lo.reversal_fraction = reversal_fraction;
  lo.min_span_fraction = min_span_fraction;
  return json_to_py(models::loops_json(models::find_loops(xv, fv, lo)));
}

}  // namespace

void bind_identify(py::module_& m) {
  using py::arg;
  m.def("identify_virtual", &identify_virtual, arg("params"), py::kw_only(), arg("range") = py::none(), arg("subdivisions") = py::none(),
        arg("refine") = py::none(), arg("nodes") = py::none(),
        "The table of the simplified model from a virtual FOT campaign (hystlab identify --model simplified).");
  m.def("identify_from_nodes", &identify_from_nodes, arg("alpha_mm"), arg("beta_mm"), arg("force_alpha_N"), arg("force_alpha_beta_N"), py::kw_only(),
        arg("noise") = py::none(), arg("origin") = "hystlab Python module", arg("details") = false,
        "A table from measured FOT nodes (hystlab identify --fot); details=True also returns the drift and violations.");
  m.def("fit", &fit, arg("x"), arg("f"), py::kw_only(), arg("subdivisions") = py::none(), arg("range") = py::none(), arg("refine") = py::none(),
        arg("nodes") = py::none(), arg("prior") = "auto", arg("lambda_") = py::none(), arg("folds") = 4, arg("origin") = "hystlab Python module",
        "The least-squares table of a displacement/force record (hystlab fit).");
  m.def("calibrate", &calibrate, arg("x"), arg("f"), py::kw_only(), arg("initial") = py::none(), arg("temperature") = py::none(), arg("clausius") = py::none(),
        arg("origin") = "hystlab Python module", arg("details") = false, "Simplified-model parameters from one measured loop (hystlab calibrate).");
}

void bind_measures(py::module_& m) {
  using py::arg;
  m.def("compare", &compare, arg("x"), arg("reference"), arg("model"),
        "Accuracy of model forces against reference forces, overall and per branch (hystlab compare).");
  m.def(
      "path_work",
      [](const py::handle& x, const py::handle& f) {
        const auto xv = finite_vector(x, "x"), fv = finite_vector(f, "f");
        if (xv.size() != fv.size()) throw std::invalid_argument("x and f must have the same length");
        return models::path_work(xv, fv);
      },
      arg("x"), arg("f"), "Trapezoidal ∫ f dx along the path, N·mm.");
  m.def("loops", &loops, arg("x"), arg("f"), py::kw_only(), arg("plateaus") = std::vector<double>{}, arg("reversal_fraction") = 0.01,
        arg("min_span_fraction") = 0.02, "The figures of every closed cycle of a record (hystlab loops --json).");
  m.def(
      "loop_transformation",
      [](const py::handle& x, const py::handle& f) -> py::object {
        const auto xv = finite_vector(x, "x"), fv = finite_vector(f, "f");
        const auto t = models::loop_transformation(xv, fv);
        return t ? py::object(transitions_to_dict(*t)) : py::none();
      },
      arg("x"), arg("f"), "Ms, Mf, As, Af of one loop by tangent intersection, or None without plateaus.");
}

}  // namespace hystlab::python
