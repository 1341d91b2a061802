// hystlab simulate sdof: the base-excited isolator of the paper's Part II (models/sdof.hpp):
// time histories, or a transmissibility sweep up and down next to linear spring-dampers of
// matched static stiffness.
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>
#include "hystlab/models/formats.hpp"

#include "cli_support.hpp"
#include "commands.hpp"
#include "hystlab/models/linear_spring.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/sdof.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "svg_plot.hpp"

namespace hystlab::cli {
namespace {
const char* kSimulateHelp = R"(usage: hystlab simulate sdof --mass KG --amplitude-mm Y SPRING [options] (--frequency-hz F --duration-s T | --sweep RANGE)

A mass on N springs over a base moving as y = Y sin(2πft) (mm, N, kg, s). The springs carry the
weight at the preload; their compression is preload + y − x and they only push.
  SPRING:  --table T.json | --model simplified [--params P.json] | --linear K_N_per_mm
           | --tables T1.json,T2.json,...  (one calibrated table per spring)
  --springs N         springs in parallel, each the model above (default 1)
  --damping C         a linear damper beside them, N·s/mm (default 0)
  --preload-mm D      static compression under the weight (default 0)
  --dt S              the fixed step (default 1e-4 s); an unstable step is refused
Time history: --frequency-hz F --duration-s T [--every K] writes
  t_s,base_mm,mass_mm,compression_mm,force_N,input_work_Nmm,spring_work_Nmm,damper_work_Nmm,kinetic_Nmm,gravity_Nmm
  (every K-th step) to -o H.csv or standard output.
Sweep: --sweep with --frequencies a,b,... or --from-hz A --to-hz B [--steps 20] [--log]
  [--settle-cycles 20] [--measured-cycles 10] [--zetas 0.05,0.1,0.2,0.4] [--svg S.svg]
  Steady transmissibility (mass/base amplitude at the base frequency) sweeping up, then down,
  carrying the state from step to step; and the same sweep of a linear spring-damper with the
  same static deflection under the same weight (needs --preload-mm > 0) per damping ratio.
  Writes frequency_hz,up,down,up_p2p,down_p2p,linear_zeta_Z... to -o S.csv or standard output.
)";

// An upper bound of the tangent stiffness, for the stability check.
double stiffness_bound(const models::HysteresisModel& m) {
  if (const auto* p = dynamic_cast<const models::PreisachModel*>(&m)) return models::max_stiffness(p->table());
  if (const auto* s = dynamic_cast<const models::SimplifiedSmaModel*>(&m)) return std::max(s->parameters().KA, s->parameters().KM);
  if (const auto* l = dynamic_cast<const models::LinearSpring*>(&m)) return l->stiffness();
  throw CliError("no stiffness bound for this model");
}

std::unique_ptr<models::HysteresisModel> spring_model(const Options& opt, std::string& description) {
  if (opt.has("linear")) {
    if (opt.has("table") || opt.has("model")) throw CliError("give one spring: --table, --model or --linear");
    const double k = opt.number("linear", 0);
    description = "linear spring " + format_number(k) + " N/mm";
    try {
      return std::make_unique<models::LinearSpring>(k);
    } catch (const std::invalid_argument& e) {
      throw CliError(std::string("--linear: ") + e.what());
    }
  }
  LoadedModel m = load_model(opt);
  description = m.description;
  return std::move(m.model);
}

using Springs = std::vector<std::shared_ptr<const models::HysteresisModel>>;  // one prototype per spring

models::SdofSystem make_system(const Springs& protos, const models::SdofOptions& o) {
  std::vector<models::SdofSpring> springs;
  for (const auto& p : protos) springs.push_back({p->clone(), stiffness_bound(*p)});
  try {
    return models::SdofSystem(std::move(springs), o);
  } catch (const std::invalid_argument& e) {
    throw CliError(e.what());
  }
}

std::vector<double> list(const std::string& text, const char* what) {
  std::vector<double> v;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    char* end = nullptr;
    const double x = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(x)) throw CliError(std::string(what) + ": '" + item + "' is not a number");
    v.push_back(x);
  }
  if (v.empty()) throw CliError(std::string(what) + ": empty list");
  return v;
}

std::vector<double> sweep_frequencies(const Options& opt) {
  if (opt.has("frequencies")) return list(opt.get("frequencies"), "--frequencies");
  const double a = opt.number("from-hz", 0), b = opt.number("to-hz", 0);
  const int n = opt.integer("steps", 20, 2, 10000);
  if (!(a > 0) || !(b > a)) throw CliError("--from-hz and --to-hz: need 0 < from < to (or give --frequencies)");
  std::vector<double> f;
  for (int k = 0; k < n; ++k) f.push_back(opt.has("log") ? a * std::pow(b / a, k / double(n - 1)) : a + (b - a) * k / double(n - 1));
  return f;
}

// Up then down over the list, carrying the state: jumps show up as a difference.
std::pair<std::vector<models::SteadyResponse>, std::vector<models::SteadyResponse>> sweep(models::SdofSystem sys, double y, const std::vector<double>& f,
                                                                                          int settle, int measured) {
  std::vector<models::SteadyResponse> up, down(f.size());
  try {
    for (double fr : f) up.push_back(models::steady_response(sys, y, fr, settle, measured));
    for (std::size_t k = f.size(); k-- > 0;) down[k] = models::steady_response(sys, y, f[k], settle, measured);
  } catch (const std::invalid_argument& e) {
    throw CliError(e.what());
  }
  return {up, down};
}

int run_sweep(const Options& opt, const Springs& protos, const models::SdofOptions& o, double y, const std::string& what) {
  const int n = static_cast<int>(protos.size());
  const std::vector<double> f = sweep_frequencies(opt);
  const int settle = opt.integer("settle-cycles", 20, 0, 100000), measured = opt.integer("measured-cycles", 10, 1, 100000);
  const auto [up, down] = sweep(make_system(protos, o), y, f, settle, measured);
  std::vector<std::string> header{"frequency_hz", "up", "down", "up_p2p", "down_p2p"};
  std::vector<std::vector<double>> cols(5);
  for (std::size_t k = 0; k < f.size(); ++k) {
    cols[0].push_back(f[k]), cols[1].push_back(up[k].ratio), cols[2].push_back(down[k].ratio);
    cols[3].push_back(up[k].peak_to_peak_ratio), cols[4].push_back(down[k].peak_to_peak_ratio);
  }
  std::vector<PlotSeries> plot{{"SMA isolator, sweep up", "#1565c0", f, cols[1]}, {"SMA isolator, sweep down", "#c62828", f, cols[2], true}};
  const std::vector<double> zetas = list(opt.get("zetas", "0.05,0.1,0.2,0.4"), "--zetas");
  if (o.preload_mm > 0) {
    const models::SdofSystem probe = make_system(protos, o);
    const double k_eq = probe.weight_N() / n / o.preload_mm;  // same static deflection under the same weight
    const double wn = std::sqrt(1000.0 * n * k_eq / o.mass_kg);
    const char* colours[] = {"#2e7d32", "#6a1b9a", "#ef6c00", "#00838f", "#5d4037", "#455a64"};
    for (std::size_t z = 0; z < zetas.size(); ++z) {
      if (!(zetas[z] >= 0) || zetas[z] > 10) throw CliError("--zetas: damping ratios from 0 to 10");
      models::SdofOptions lo = o;
      lo.damping_N_s_per_mm = 2 * zetas[z] * o.mass_kg * wn / 1000.0;
      const Springs linear(protos.size(), std::make_shared<models::LinearSpring>(k_eq));
      const auto [lup, ldown] = sweep(make_system(linear, lo), y, f, settle, measured);
      header.push_back("linear_zeta_" + format_number(zetas[z]));
      cols.emplace_back();
      for (const auto& r : lup) cols.back().push_back(r.ratio);
      plot.push_back({"linear, ζ = " + format_number(zetas[z]), colours[z % 6], f, cols.back()});
    }
    std::cerr << "hystlab: linear comparison: k = " << format_number(k_eq) << " N/mm per spring, f_n = " << format_number(wn / (2 * 3.141592653589793))
              << " Hz\n";
  } else {
    std::cerr << "hystlab: no linear comparison without --preload-mm > 0 (no static deflection to match)\n";
  }
  write_output(opt.get("output"), to_csv(header, cols));
  if (opt.has("svg")) write_file(opt.get("svg"), svg_plot("Transmissibility: " + what, "frequency (Hz)", "mass / base amplitude", plot));
  return 0;
}
}  // namespace

int run_simulate(const Args& args) {
  if (print_help_if_asked(args, kSimulateHelp) || args.empty() || args[0] != "sdof") {
    if (!args.empty() && args[0] != "sdof" && args[0] != "--help" && args[0] != "-h") throw CliError("unknown simulation '" + args[0] + "' (known: sdof)");
    if (args.empty()) std::cout << kSimulateHelp;
    return args.empty() ? 2 : 0;
  }
  const Options opt(Args(args.begin() + 1, args.end()),
                    {"mass",       "springs", "table",         "tables",          "model",      "params", "linear",      "damping",
                     "preload-mm", "dt",      "amplitude-mm",  "frequency-hz",    "duration-s", "every",  "frequencies", "from-hz",
                     "to-hz",      "steps",   "settle-cycles", "measured-cycles", "zetas",      "svg",    "output"},
                    {"sweep", "log"});
  models::SdofOptions o;
  if (!opt.has("mass")) throw CliError("--mass KG is required");
  o.mass_kg = opt.number("mass", 0);
  o.damping_N_s_per_mm = opt.number("damping", 0);
  o.preload_mm = opt.number("preload-mm", 0);
  o.dt_s = opt.number("dt", 1e-4);
  const int n = opt.integer("springs", 1, 1, 10000);
  const double y = opt.number("amplitude-mm", 0);
  if (!(y > 0)) throw CliError("--amplitude-mm: a positive base amplitude is required");
  std::string what;
  Springs protos;
  if (opt.has("tables")) {  // one calibrated table per spring
    if (opt.has("table") || opt.has("model") || opt.has("linear") || opt.has("springs"))
      throw CliError("--tables gives one table per spring: no --table, --model, --linear or --springs with it");
    std::stringstream in(opt.get("tables"));
    for (std::string path; std::getline(in, path, ',');) {
      const auto doc = read_table_file(path);
      protos.push_back(std::make_shared<models::PreisachModel>(doc.table));
    }
    what = std::to_string(protos.size()) + " calibrated tables";
  } else {
    const std::shared_ptr<const models::HysteresisModel> proto = spring_model(opt, what);
    protos.assign(static_cast<std::size_t>(n), proto);
  }
  if (opt.has("sweep")) return run_sweep(opt, protos, o, y, what);
  models::SdofSystem sys = make_system(protos, o);
  const double f = opt.number("frequency-hz", 0), duration = opt.number("duration-s", 0);
  if (!(f > 0) || !(duration > 0)) throw CliError("--frequency-hz and --duration-s: positive numbers (or --sweep)");
  const int every = opt.integer("every", 10, 1, 1000000);
  sys.set_base(y, f);
  std::vector<std::vector<double>> cols(10);
  const auto steps = static_cast<long>(std::llround(duration / o.dt_s));
  for (long k = 0; k <= steps; ++k) {
    if (k > 0) sys.step();
    if (k % every) continue;
    const auto& s = sys.state();
    const auto& e = sys.energy();
    for (auto [c, v] :
         {std::pair{0, s.t}, {1, s.y}, {2, s.x}, {3, s.delta}, {4, s.force}, {5, e.input}, {6, e.spring}, {7, e.damper}, {8, e.kinetic}, {9, e.gravity}})
      cols[static_cast<std::size_t>(c)].push_back(v);
  }
  write_output(opt.get("output"), to_csv({"t_s", "base_mm", "mass_mm", "compression_mm", "force_N", "input_work_Nmm", "spring_work_Nmm", "damper_work_Nmm",
                                          "kinetic_Nmm", "gravity_Nmm"},
                                         cols));
  if (sys.lift_off_steps()) std::cerr << "hystlab: the mass left the springs during " << sys.lift_off_steps() << " steps\n";
  return 0;
}

}  // namespace hystlab::cli
