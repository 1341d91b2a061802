// hystlab identify / fit / calibrate: tables and parameters from models or data.
#include <iostream>
#include <sstream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "hystlab/models/fit_report.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "hystlab/models/sma_calibration.hpp"

namespace hystlab::cli {

namespace {
const char* kIdentifyHelp = R"(usage: hystlab identify --model simplified [--params P.json] --range A,B --subdivisions N
                         [--refine CENTER,WIDTH[,SHARE] | --nodes D0,D1,...,Dn] -o T.json
       hystlab identify --fot nodes.csv [--noise SIGMA_N] -o T.json

Virtual campaign: runs the FOT identification input (to δmin, up to each δ_i, down through every
δ_j) on the model and tabulates F(α,β) (MODELS.md §3). Without --params, Table 1.
The grid is n equal steps of the range, or a grid of its own (table format version 2): --refine
puts SHARE (default 0.5) of the n steps evenly in [CENTER - WIDTH/2, CENTER + WIDTH/2], around an
operating preload say, and spreads the rest outside it; --nodes gives every node (the range and
n are then the nodes').
From measured nodes: columns alpha_mm,beta_mm,force_alpha_N,force_alpha_beta_N. Repeated nodes
are averaged; the spread of repeated f_α is the drift figure; cells whose Preisach weight is
negative beyond noise (--noise, default: the drift figure) are reported.
)";

const char* kFitHelp = R"(usage: hystlab fit --data X.csv (--subdivisions N [--range A,B] [--refine C,W[,SHARE]] | --nodes D0,...,Dn)
                  [--prior auto|signed|monotone] [--lambda L] [--folds K] -o T.json

Least-squares Preisach table from any displacement/force record (columns displacement_mm,
force_N), F(α,α) = 0. The prior is the model class: `signed` lets cell masses take either sign
(a superelastic specimen needs it), `monotone` holds every mass >= 0 (the classical Preisach
measure), `auto` (the default) fits both and keeps the one with the lower error on held-out
blocks of the record. The smoothing weight is chosen by K-fold cross-validation on contiguous
blocks (default 4) unless --lambda is given. N at most 200. The range defaults to the data's
displacement range. The record is assumed to start from rest at the bottom of the range.
--refine and --nodes give a grid of its own, as for identify. Above 200,000 samples, the prior and
lambda are chosen (and sigma estimated) on the record thinned to about 200,000 with every turning
point kept; the chosen prior's table is then fitted on every sample.
)";

const char* kCalibrateHelp = R"(usage: hystlab calibrate --data loop.csv (--initial P.json | --temperature T --clausius C) -o P.json

Fits the simplified SMA model to one measured loop (columns displacement_mm, force_N) that loads
past the end of the forward transformation and unloads below the end of the reverse one.
One isothermal loop fixes KA, KM, dtr_max and the four transition forces; C (N/°C) and T (°C)
come from --initial or the options, and the transition temperatures are derived from them.
)";

std::string grid_text(const models::Grid& g) {
  std::ostringstream s;
  s << "n = " << g.n << " on " << format_number(g.lo) << ".." << format_number(g.hi) << " mm";
  if (!g.uniform()) {
    s << ", nodes";
    for (int i = 0; i <= g.n; ++i) s << (i ? ", " : " ") << format_number(g.node(i));
    s << " mm";
  }
  return s.str();
}

// --range and --subdivisions, refined by --refine, or --nodes.
models::Grid grid_option(const Options& opt) {
  try {
    if (opt.has("nodes")) {
      if (opt.has("range") || opt.has("subdivisions") || opt.has("refine"))
        throw CliError("--nodes gives the whole grid: leave out --range, --subdivisions and --refine");
      return models::Grid::from_nodes(opt.numbers("nodes"));
    }
    const auto [lo, hi] = opt.range("range");
    if (!opt.has("subdivisions")) throw CliError("missing required option --subdivisions");
    const int n = opt.integer("subdivisions", 0, 1, 2000);
    if (!opt.has("refine")) return models::Grid::make(lo, hi, n);
    const std::vector<double> r = opt.numbers("refine");
    if (r.size() != 2 && r.size() != 3) throw CliError("option --refine: expected CENTER,WIDTH or CENTER,WIDTH,SHARE");
    return models::Grid::refined(lo, hi, n, r[0], r[1], r.size() == 3 ? r[2] : 0.5);
  } catch (const std::invalid_argument& e) {
    throw CliError(std::string(opt.has("nodes") ? "option --nodes: " : opt.has("refine") ? "option --refine: " : "") + e.what());
  }
}
}  // namespace

int run_identify(const Args& args) {
  if (print_help_if_asked(args, kIdentifyHelp)) return 0;
  const Options opt(args, {"model", "params", "range", "subdivisions", "fot", "noise", "output", "refine", "nodes"}, {});
  const std::string out = opt.require("output");
  models::TableProvenance prov;
  prov.created = now_iso8601();
  models::EverettTable table;
  if (opt.has("fot")) {
    if (opt.has("model")) throw CliError("give either --fot or --model, not both");
    const std::string path = opt.require("fot");
    const Csv csv = Csv::load(path);
    const auto a = csv.column("alpha_mm"), b = csv.column("beta_mm");
    const auto fa = csv.column("force_alpha_N"), fab = csv.column("force_alpha_beta_N");
    std::vector<models::FotNode> nodes;
    for (std::size_t k = 0; k < a.size(); ++k) nodes.push_back(models::FotNode{a[k], b[k], fa[k], fab[k]});
    const double noise = opt.number("noise", -1.0);
    if (opt.has("noise") && noise < 0) throw CliError("option --noise: must be >= 0");
    const models::FotIdentification id = models::identify_from_nodes(nodes, noise);
    table = id.table;
    prov.source = "measured FOT nodes";
    prov.method = "fot";
    prov.from = path;
    prov.extra = {{"nodes", id.node_count},
                  {"drift_max_spread_N", id.drift.max_spread},
                  {"drift_pooled_std_N", id.drift.pooled_std},
                  {"violations", id.violations.size()}};
    std::cout << "identified " << grid_text(table.grid()) << " from " << id.node_count << " nodes\n"
              << "drift: max spread of f_alpha " << format_number(id.drift.max_spread) << " N, pooled std " << format_number(id.drift.pooled_std) << " N over "
              << id.drift.repeated_rows << " repeated rows\n";
    for (const auto& c : id.violations)
      std::cout << "warning: cell alpha in [" << format_number(table.grid().node(c.p - 1)) << ", " << format_number(table.grid().node(c.p)) << "] beta in ["
                << format_number(table.grid().node(c.q - 1)) << ", " << format_number(table.grid().node(c.q)) << "] has weight " << format_number(c.weight)
                << " N (below -" << format_number(id.violation_threshold) << " N): F is not monotone there\n";
  } else {
    LoadedModel m = load_model(opt);
    const models::Grid g = grid_option(opt);
    table = models::identify_virtual(*m.model, g);
    prov.source = m.description;
    prov.method = "virtual-fot";
    prov.from = opt.get("params", "built-in Table 1");
    if (const auto* sma = dynamic_cast<const models::SimplifiedSmaModel*>(m.model.get())) prov.temperature_C = sma->parameters().T;
    std::cout << "identified " << grid_text(g) << " (" << g.node_count() << " nodes) from the " << m.description << "\n";
  }
  write_file(out, models::table_to_json(table, prov).dump(2) + "\n");
  std::cout << "wrote " << out << "\n";
  return 0;
}

int run_fit(const Args& args) {
  if (print_help_if_asked(args, kFitHelp)) return 0;
  const Options opt(args, {"data", "subdivisions", "range", "lambda", "output", "prior", "folds", "refine", "nodes"}, {});
  const std::string out = opt.require("output"), path = opt.require("data");
  const Csv csv = Csv::load(path);
  const auto x = csv.column("displacement_mm"), y = csv.column("force_N");
  models::PreisachFitOptions fo;
  models::Grid grid;
  if (opt.has("nodes")) {
    grid = grid_option(opt);
    if (grid.n > fo.max_subdivisions) throw CliError("option --nodes: at most " + std::to_string(fo.max_subdivisions + 1) + " nodes");
  } else {
    if (!opt.has("subdivisions")) throw CliError("missing required option --subdivisions");
    const int n = opt.integer("subdivisions", 0, 1, fo.max_subdivisions);
    double lo = *std::min_element(x.begin(), x.end()), hi = *std::max_element(x.begin(), x.end());
    if (opt.has("range")) std::tie(lo, hi) = opt.range("range");
    if (!(hi > lo)) throw CliError(path + ": the displacement never changes");
    grid = models::Grid::make(lo, hi, n);
    if (opt.has("refine")) {
      const std::vector<double> r = opt.numbers("refine");
      if (r.size() != 2 && r.size() != 3) throw CliError("option --refine: expected CENTER,WIDTH or CENTER,WIDTH,SHARE");
      try {
        grid = models::Grid::refined(lo, hi, n, r[0], r[1], r.size() == 3 ? r[2] : 0.5);
      } catch (const std::invalid_argument& e) {
        throw CliError(std::string("option --refine: ") + e.what());
      }
    }
  }
  fo.lambda = opt.number("lambda", -1.0);
  if (opt.has("lambda") && fo.lambda < 0) throw CliError("option --lambda: must be >= 0");
  fo.folds = opt.integer("folds", 4, 2, 20);
  try {
    fo.prior = models::fit_prior_from_string(opt.get("prior", "auto"));
  } catch (const std::invalid_argument& e) {
    throw CliError(std::string("option --") + e.what());
  }
  const models::PreisachFitResult r = models::fit_preisach(x, y, grid, fo);
  const models::PriorFit& c = r.chosen;
  models::TableProvenance prov{"displacement/force record", "lsq", now_iso8601(), path, models::fit_provenance(r), {}};
  write_file(out, models::table_to_json(c.table, prov).dump(2) + "\n");
  std::cout << "fitted " << grid_text(c.table.grid()) << " to " << x.size() << " samples in " << format_number(r.seconds) << " s ("
            << format_number(static_cast<double>(r.peak_bytes) / 1048576.0) << " MiB)"
            << (r.selection_samples < x.size()
                    ? "; the prior and lambda chosen on " + std::to_string(r.selection_samples) + " of them (every turning point kept)"
                    : std::string())
            << "\n"
            << "prior " << models::to_string(c.prior) << ": " << r.reason << "\n"
            << "smoothing lambda " << format_number(c.lambda) << (opt.has("lambda") ? " (given)" : " (" + std::to_string(fo.folds) + "-fold cross-validation)")
            << "\n"
            << "residual: rms " << format_number(c.rms_residual) << " N, max " << format_number(c.max_residual)
            << " N; cells of negative mass: " << c.negative_cells << ", held at zero: " << c.cells_at_bound << " of " << c.cell_weight.size() << "\n"
            << "wrote " << out << "\n";
  return 0;
}

int run_calibrate(const Args& args) {
  if (print_help_if_asked(args, kCalibrateHelp)) return 0;
  const Options opt(args, {"data", "initial", "temperature", "clausius", "output"}, {});
  const std::string out = opt.require("output"), path = opt.require("data");
  models::SmaCalibrationOptions co;
  if (opt.has("initial")) {
    const models::SmaParameters p = read_params_file(opt.require("initial"));
    co.C = p.C;
    co.T = p.T;
  } else if (!opt.has("temperature") || !opt.has("clausius")) {
    throw CliError("calibrate needs --initial P.json, or both --temperature T and --clausius C");
  }
  co.T = opt.number("temperature", co.T);
  co.C = opt.number("clausius", co.C);
  if (!(co.C > 0)) throw CliError("option --clausius: must be > 0");
  const Csv csv = Csv::load(path);
  const auto x = csv.column("displacement_mm"), y = csv.column("force_N");
  const models::SmaCalibration c = models::calibrate_simplified_sma(x, y, co);
  write_file(out, models::params_to_json(c.parameters, "calibrated from " + path).dump(2) + "\n");
  const auto& p = c.parameters;
  std::cout << "KA " << format_number(p.KA) << " N/mm, KM " << format_number(p.KM) << " N/mm, dtr_max " << format_number(p.dtr_max) << " mm\n"
            << "transition forces: Ms " << format_number(c.transitions.Ms.force) << " N, Mf " << format_number(c.transitions.Mf.force) << " N, As "
            << format_number(c.transitions.As.force) << " N, Af " << format_number(c.transitions.Af.force) << " N\n"
            << "temperatures (C = " << format_number(p.C) << " N/degC, T = " << format_number(p.T) << " degC): Mf0 " << format_number(p.Mf0) << ", Ms0 "
            << format_number(p.Ms0) << ", As0 " << format_number(p.As0) << ", Af0 " << format_number(p.Af0) << "\n"
            << "residual: rms " << format_number(c.rms_residual) << " N, max " << format_number(c.max_residual) << " N after " << c.iterations
            << " iterations\n"
            << "wrote " << out << "\n";
  return 0;
}

}  // namespace hystlab::cli
