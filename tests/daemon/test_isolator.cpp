// The isolator a shaker carries, as the daemon predicts it: springs from simplified-model
// parameters, from a linear stiffness, or from a Preisach table identified on a load frame (the
// mission's chain: identify the springs on the frame, predict the isolator on the shaker).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>

#include "../support/temp_dir.hpp"
#include "hystlab/daemon/isolator.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/linear_spring.hpp"
#include "hystlab/models/sdof.hpp"
#include "hystlab/models/simplified_sma.hpp"

using namespace hystlab;
using nlohmann::json;

namespace {
std::vector<daemon::PredictStep> steps_at(std::initializer_list<double> f, double amplitude) {
  std::vector<daemon::PredictStep> out;
  for (const double x : f) out.push_back({x, amplitude, 30, 10});
  return out;
}
// A table identified from Table 1's simplified model on a virtual load frame (as hystlab identify does).
json table1_table(int n) {
  models::SimplifiedSmaModel spring(models::table1_parameters());
  const models::EverettTable t = models::identify_virtual(spring, models::Grid::make(0, 4, n));
  return models::table_to_json(t, {"the simplified model, Table 1, on a virtual frame", "virtual-fot", "2026-11-26T00:00:00Z", "test", json::object()});
}
}  // namespace

TEST_CASE("isolator: linear springs predict the analytic transmissibility") {
  const daemon::IsolatorModel iso = daemon::parse_isolator({{"mass_kg", 13}, {"springs", 4}, {"damping_N_s_per_m", 58}, {"linear_N_per_mm", 40}}, "isolator");
  CHECK(iso.describe.find("linear, 40 N/mm") != std::string::npos);
  const double fn = std::sqrt(4 * 40e3 / 13.0) / (2 * std::numbers::pi), zeta = 58 / (2 * std::sqrt(4 * 40e3 * 13.0));
  const auto steps = steps_at({8, 15, 17.5, 20, 40}, 0.01);
  const auto p = daemon::predict_sweep(iso, steps);
  REQUIRE(p.size() == steps.size());
  for (std::size_t k = 0; k < p.size(); ++k) {
    CAPTURE(steps[k].frequency_hz);
    CHECK(p[k].ratio == doctest::Approx(models::linear_transmissibility(steps[k].frequency_hz / fn, zeta)).epsilon(0.01));
  }
}

TEST_CASE("isolator: springs from a table identified on the load frame predict what the springs themselves do") {
  test_support::TempDir dir("isolator");
  const std::string file = (dir.path() / "S-07.json").string();
  std::ofstream(file) << table1_table(80).dump();
  const daemon::IsolatorModel from_table = daemon::parse_isolator({{"table", file}}, "isolator");
  CHECK(from_table.describe.find("Preisach table n = 80 (virtual-fot, " + file + ": the simplified model, Table 1, on a virtual frame)") != std::string::npos);
  const daemon::IsolatorModel from_params = daemon::parse_isolator(json::object(), "isolator");  // Table 1 itself
  // Swept through the resonance at an amplitude that moves the springs' state (0.05 mm): the peak
  // where the springs themselves put it, and the ratio well below and above it. A table's small
  // loops are its cells' (bilinear within 0.05 mm at n = 80): on the resonance's flanks, where the
  // ratio changes 30 % a hertz, that shows as up to 10 % (n = 40: 16 Hz read 4.98 for 4.53).
  std::vector<daemon::PredictStep> sweep;
  for (double f = 14; f <= 22.01; f += 0.25) sweep.push_back({f, 0.05, 30, 10});
  const auto t = daemon::predict_sweep(from_table, sweep), m = daemon::predict_sweep(from_params, sweep);
  auto peak = [&](const std::vector<daemon::Predicted>& p) {
    return sweep[static_cast<std::size_t>(std::max_element(p.begin(), p.end(), [](auto& a, auto& b) { return a.ratio < b.ratio; }) - p.begin())].frequency_hz;
  };
  CAPTURE(peak(t));
  CAPTURE(peak(m));
  CHECK(std::fabs(peak(t) / peak(m) - 1) < 0.03);
  const auto far = steps_at({8, 40}, 0.05);
  const auto tf = daemon::predict_sweep(from_table, far), mf = daemon::predict_sweep(from_params, far);
  for (std::size_t k = 0; k < far.size(); ++k) {
    CAPTURE(far[k].frequency_hz);
    CAPTURE(tf[k].ratio);
    CAPTURE(mf[k].ratio);
    CHECK(std::fabs(tf[k].ratio / mf[k].ratio - 1) < 0.05);
  }
  // Inline, the same document.
  const daemon::IsolatorModel inline_table = daemon::parse_isolator({{"table", table1_table(80)}}, "isolator");
  CHECK(daemon::predict_sweep(inline_table, far)[1].ratio == doctest::Approx(tf[1].ratio));
}

TEST_CASE("isolator: the table is what predicts: a linear spring's table gives the analytic transmissibility") {
  // 80 N/mm springs (f_n 25 Hz), where Table 1's springs would put it near 17.7 Hz. Off the
  // resonance: there the peak is set by the damping, and a table's cells add a little of their
  // own (bilinear within a cell is a small loop): 18.8 for 23.0 at 17.5 Hz with 40 N/mm springs.
  models::LinearSpring linear(80);
  const models::EverettTable tab = models::identify_virtual(linear, models::Grid::make(0, 4, 20));
  const json doc = models::table_to_json(tab, {"an 80 N/mm spring on a virtual frame", "virtual-fot", "2026-11-26T00:00:00Z", "test", json::object()});
  const daemon::IsolatorModel iso = daemon::parse_isolator({{"table", doc}}, "isolator");
  const double fn = std::sqrt(4 * 80e3 / 13.0) / (2 * std::numbers::pi), zeta = 58 / (2 * std::sqrt(4 * 80e3 * 13.0));
  const auto steps = steps_at({8, 15, 40, 60}, 0.05);
  const auto p = daemon::predict_sweep(iso, steps);
  for (std::size_t k = 0; k < p.size(); ++k) {
    CAPTURE(steps[k].frequency_hz);
    CHECK(p[k].ratio == doctest::Approx(models::linear_transmissibility(steps[k].frequency_hz / fn, zeta)).epsilon(0.02));
  }
}

TEST_CASE("isolator: a spring given two ways, a file that is not there, a document that is not a table: named") {
  auto refusal = [](const json& j) {
    try {
      (void)daemon::parse_isolator(j, "rigs[1].isolator");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK(refusal({{"table", "x.json"}, {"linear_N_per_mm", 40}}).find("rigs[1].isolator gives its springs one way") != std::string::npos);
  CHECK(refusal({{"table", "/no/such/S-07.json"}}).find("rigs[1].isolator.table names a file that cannot be read") != std::string::npos);
  CHECK(refusal({{"table", {{"format", "nothing"}}}}).find("rigs[1].isolator.table is not a table document") != std::string::npos);
  CHECK(refusal({{"linear_N_per_mm", -1}}).find("rigs[1].isolator.linear_N_per_mm must be a number above 0") != std::string::npos);
  CHECK(refusal({{"table", 7}}).find("rigs[1].isolator.table gives a stored table's id, which only a sine plan's isolator can") != std::string::npos);
  // A plan's isolator: a stored table by id, looked up in the store.
  const auto lookup = [](std::int64_t id) -> std::optional<std::string> {
    if (id == 7) return table1_table(12).dump();
    return std::nullopt;
  };
  const daemon::IsolatorModel stored = daemon::parse_isolator({{"table", 7}}, "isolator", lookup);
  CHECK(stored.describe.find("Preisach table n = 12 (virtual-fot, table 7: the simplified model") != std::string::npos);
  // The rig's mass, springs and damper unless the plan gives them; no file opened for a plan.
  daemon::IsolatorModel rig;
  rig.mass_kg = 20, rig.springs = 6, rig.damping_N_s_per_m = 80;
  const daemon::IsolatorModel on_rig = daemon::parse_isolator({{"table", 7}, {"springs", 3}}, "isolator", lookup, &rig);
  CHECK(on_rig.mass_kg == 20);
  CHECK(on_rig.springs == 3);
  CHECK(on_rig.damping_N_s_per_m == 80);
  try {
    (void)daemon::parse_isolator({{"table", "/etc/passwd"}}, "isolator", lookup);
    FAIL("a plan opened a file of the daemon's host");
  } catch (const daemon::IsolatorError& e) {
    CHECK(std::string(e.what()).find("isolator.table must be a stored table's id or a table document in a plan") == 0);
  }
  try {
    (void)daemon::parse_isolator({{"table", 8}}, "isolator", lookup);
    FAIL("a table the store does not hold was taken");
  } catch (const daemon::IsolatorError& e) {
    CHECK(e.field == "isolator.table");
    CHECK(std::string(e.what()) == "isolator.table names table 8, which this daemon's store does not hold");
  }
}
