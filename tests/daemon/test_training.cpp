// Training until stable, held-out validation and loop plateaus in the plan: the pure parts (the
// plan's fields, the stabilisation rule, the validation input, the schedule).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "hystlab/daemon/sequencer.hpp"
#include "hystlab/daemon/shakedown.hpp"
#include "hystlab/domain/plan.hpp"

using namespace hystlab;
using nlohmann::json;

namespace {
json training_plan(json extra) {
  json p{{"kind", "fot"}, {"range_mm", {0, 4}}, {"subdivisions", 4}};
  for (auto& [k, v] : extra.items()) p[k] = v;
  return p;
}

void refused(const json& extra, const std::string& field, const std::string& part) {
  CAPTURE(extra.dump());
  try {
    (void)domain::parse_plan(training_plan(extra));
    FAIL("accepted");
  } catch (const domain::PlanError& e) {
    CHECK(e.field == field);
    CHECK(std::string(e.what()).find(part) != std::string::npos);
  }
}
}  // namespace

TEST_CASE("plan: training until stable, validation and plateaus, each refusal naming its field") {
  json extra;
  extra["training"] = {{"max_cycles", 40}, {"until", {{"peak_force_change", "0.5 %"}, {"energy_change", 2}, {"consecutive", 3}}}};
  extra["validation"] = {{"reversals", 20}, {"range_mm", {0.5, 3.5}}, {"seed", 7}};
  extra["plateaus_mm"] = {1, 3};
  const auto p = domain::parse_plan(training_plan(extra));
  CHECK(p.training.max_cycles == 40);
  CHECK(p.training.until);
  CHECK(p.training.peak_force_change_pct == 0.5);
  CHECK(p.training.energy_change_pct == 2.0);
  CHECK(p.validation.enabled);
  CHECK(p.validation.reversals == 20);
  CHECK(p.validation.lo_mm == 0.5);
  CHECK(p.validation.seed == 7);
  CHECK(p.validation.rate_mm_s == p.ramp_rate_mm_s);
  CHECK(p.plateaus_mm == std::vector<double>{1, 3});
  // Defaults: validation on over the plan's range; training_cycles is a fixed count.
  const auto d = domain::parse_plan(training_plan({{"training_cycles", 3}}));
  CHECK(d.validation.enabled);
  CHECK(d.validation.hi_mm == 4.0);
  CHECK(d.training.max_cycles == 3);
  CHECK_FALSE(d.training.until);
  CHECK_FALSE(domain::parse_plan(training_plan({{"validation", false}})).validation.enabled);
  refused({{"training", {{"max_cycles", 0}}}}, "training.max_cycles", "from 1 to 1000");
  refused({{"training", {{"max_cycles", 5}, {"until", {{"energy_change", "two"}}}}}}, "training.until.energy_change", "percentage");
  refused({{"training", {{"max_cycles", 5}, {"until", {{"peak_force_change", -1}}}}}}, "training.until.peak_force_change", "percentage");
  refused({{"training", {{"max_cycles", 5}, {"until", {{"consecutive", 5}}}}}}, "training.until.consecutive", "below training.max_cycles");
  refused({{"training", {{"max_cycles", 5}, {"until", {{"stable", true}}}}}}, "training.until.stable", "not a known field");
  refused({{"training", {{"max_cycles", 5}}}, {"training_cycles", 2}}, "training_cycles", "give one of them");
  refused({{"validation", {{"reversals", 1}}}}, "validation.reversals", "from 2 to 10000");
  refused({{"validation", {{"range_mm", {-1, 3}}}}}, "validation.range_mm", "inside range_mm");
  refused({{"validation", "yes"}}, "validation", "or false");
  refused({{"validation", {{"seed", -3}}}}, "validation.seed", "non-negative");
  refused({{"plateaus_mm", {1, 5}}}, "plateaus_mm[1]", "inside range_mm");
  refused({{"validation", {{"rate_mm_s", 9}}}, {"limits", {{"rate_mm_s", 5}}}}, "validation.rate_mm_s", "above limits.rate_mm_s");
}

TEST_CASE("shakedown rule: stable after `consecutive` cycles below both thresholds, any change above resets the count") {
  domain::Training t;
  t.max_cycles = 20;
  t.until = true;
  t.peak_force_change_pct = 0.5;
  t.energy_change_pct = 2.0;
  t.consecutive = 3;
  daemon::ShakedownRule r(t);
  // Energy settling geometrically: 100, 90, 84, ... changes 10 %, 6.7 %, ...
  std::vector<double> energy{100, 90, 84, 81, 80.5, 80.2, 80.1, 80.05};
  std::vector<daemon::ShakedownStep> steps;
  for (double e : energy) {
    steps.push_back(r.add(150.0, e));
    if (steps.back().last) break;
  }
  REQUIRE(steps.size() == 7);
  CHECK_FALSE(steps[0].peak_change_pct);
  CHECK(*steps[1].energy_change_pct == doctest::Approx(10.0));
  // 81 -> 80.5 is 0.62 % (first below), 80.2, 80.1: the third in a row at cycle 7.
  CHECK(steps[4].consecutive == 1);
  CHECK_FALSE(steps[5].stable);
  CHECK(steps[6].stable);
  CHECK(steps[6].last);
  CHECK(r.summary().find("the loop settled after 7 training cycle(s)") == 0);
  // A peak-force jump resets the count.
  daemon::ShakedownRule q(t);
  for (double e : {80.0, 80.1, 80.2}) (void)q.add(150.0, e);
  CHECK(q.add(152.0, 80.2).consecutive == 0);
  // Randomized: the rule is met exactly when the last `consecutive` changes are all below.
  for (std::uint64_t seed = 1; seed <= 50; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> jitter(-0.03, 0.03);
    daemon::ShakedownRule u(t);
    std::vector<bool> below;
    double pe = 0, ee = 0;
    for (int c = 1; c <= t.max_cycles; ++c) {
      const double p = 150 * (1 + jitter(rng) * 0.2), e = 80 * (1 + jitter(rng));
      const auto s = u.add(p, e);
      if (c > 1) below.push_back(100 * std::fabs(p - pe) / pe < 0.5 && 100 * std::fabs(e - ee) / ee < 2.0);
      pe = p, ee = e;
      const bool expect = below.size() >= 3 && std::all_of(below.end() - 3, below.end(), [](bool b) { return b; });
      CHECK(s.stable == expect);
      if (s.stable) break;
    }
  }
  // Without `until`: every planned cycle, never "stable".
  domain::Training fixed;
  fixed.max_cycles = 2;
  daemon::ShakedownRule f(fixed);
  CHECK_FALSE(f.add(1, 1).last);
  CHECK(f.add(1, 1).last);
  CHECK(f.summary() == "trained 2 cycle(s), as planned");
}

TEST_CASE("validation input: seeded, inside its range, alternating, each move at least a tenth of the range") {
  for (std::uint64_t seed = 0; seed < 30; ++seed) {
    CAPTURE(seed);
    domain::Validation v{true, 25, 0.5, 3.5, 1.0, seed};
    const auto a = daemon::validation_points(v), b = daemon::validation_points(v);
    CHECK(a == b);
    REQUIRE(a.size() == 27);
    CHECK(a.front() == 0.5);
    CHECK(a.back() == 0.5);
    for (std::size_t k = 1; k + 1 < a.size(); ++k) {
      CAPTURE(k);
      CHECK(a[k] >= 0.5);
      CHECK(a[k] <= 3.5);
      CHECK(std::fabs(a[k] - a[k - 1]) >= 0.3 - 1e-12);
      CHECK((a[k] > a[k - 1]) == (k % 2 == 1));  // up first, then alternately
    }
    v.seed = seed + 1000;
    CHECK(daemon::validation_points(v) != a);
  }
}

TEST_CASE("schedule: training cycles, the rows, then the validation segments at their own rate") {
  auto p = domain::parse_plan(training_plan({{"training_cycles", 2}, {"validation", {{"reversals", 4}, {"rate_mm_s", 2}}}}));
  const auto s = daemon::fot_schedule(p);
  REQUIRE(s.size() == 1 + 4 + 8 + 6);
  CHECK(s[1].kind == daemon::SegmentKind::training);
  CHECK(s[5].kind == daemon::SegmentKind::rise);
  for (std::size_t k = 13; k < s.size(); ++k) {
    CHECK(s[k].kind == daemon::SegmentKind::validation);
    CHECK(s[k].rate_mm_s == 2.0);
  }
  p.validation.enabled = false;
  CHECK(daemon::fot_schedule(p).size() == 13);
}
