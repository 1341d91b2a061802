// hystlab loops: the material figures of every closed cycle of a force-displacement record.
#include <cstdio>
#include <iostream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "hystlab/models/loop_figures.hpp"
#include "hystlab/models/loop_report.hpp"

namespace hystlab::cli {
namespace {
const char* kLoopsHelp = R"(usage: hystlab loops --data X.csv [--plateaus D1,D2,...] [--json] [-o OUT]

The figures of every closed cycle in the record (columns displacement_mm and force_N): a cycle
runs from a minimum of the displacement up to a maximum and back to that minimum before the
input goes beyond the maximum (nested cycles count once each). Per cycle:
  min, max        displacement at the start and at the top, mm
  peak            the largest force in the cycle, N
  E_d             dissipated energy, the loop's area (closed oint f d(delta)), N mm
  k_sec           secant stiffness (f(max) - f(min)) / (max - min), N/mm
  zeta            equivalent viscous damping E_d / (4 pi E_s), E_s = k_sec a^2 / 2, a = (max - min) / 2
  return          the force back at the start's displacement, N
  plateaus        the force on loading and on unloading at each --plateaus displacement (ASTM F2516)
  Ms Mf As Af     transformation points by tangent intersection (three lines per branch), when
                  both branches show a plateau; the simplified model's four points
Cycles spanning less than 2 % of the record's displacement range are left out, and the input
must turn back by 1 % of it to count as a reversal. --json prints every figure as JSON.
)";

std::string fmt(double v, const char* f = "%.4g") {
  char b[40];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

std::string text_report(const std::vector<models::LoopFigures>& loops) {
  std::string s = fmt(static_cast<double>(loops.size()), "%.0f") + " closed cycle(s)\n";
  if (loops.empty()) return s;
  s += "  #   samples           min mm   max mm   peak N     E_d Nmm    k_sec N/mm  zeta     return N  residual mm\n";
  for (std::size_t k = 0; k < loops.size(); ++k) {
    const models::LoopFigures& L = loops[k];
    char line[256];
    std::snprintf(line, sizeof line, "%3zu   %7zu..%-8zu %8.4g %8.4g %8.4g %11.5g %11.5g %8.4f %9.4g %12.4g\n", k + 1, L.begin, L.end, L.min_mm, L.max_mm,
                  L.peak_force_N, L.energy_Nmm, L.secant_stiffness_N_mm, L.damping_ratio, L.return_N, L.residual_mm);
    s += line;
    for (const models::PlateauForce& p : L.plateaus)
      s += "        plateau at " + fmt(p.at_mm) + " mm: loading " + fmt(p.loading_N) + " N, unloading " + fmt(p.unloading_N) + " N\n";
    if (const auto& t = L.transformation)
      s += "        Ms (" + fmt(t->Ms.displacement) + " mm, " + fmt(t->Ms.force) + " N)  Mf (" + fmt(t->Mf.displacement) + ", " + fmt(t->Mf.force) + ")  As (" +
           fmt(t->As.displacement) + ", " + fmt(t->As.force) + ")  Af (" + fmt(t->Af.displacement) + ", " + fmt(t->Af.force) + ")\n";
  }
  return s;
}
}  // namespace

int run_loops(const Args& args) {
  if (print_help_if_asked(args, kLoopsHelp)) return 0;
  const Options opt(args, {"data", "plateaus", "output"}, {"json"});
  const std::string path = opt.require("data");
  const Csv csv = Csv::load(path);
  const auto x = csv.column("displacement_mm"), f = csv.column("force_N");
  models::LoopOptions lo;
  lo.plateau_at_mm = opt.numbers("plateaus");
  const std::vector<models::LoopFigures> loops = models::find_loops(x, f, lo);
  write_output(opt.get("output"), opt.has("json") ? models::loops_json(loops).dump(1) + "\n" : text_report(loops));
  return 0;
}

}  // namespace hystlab::cli
