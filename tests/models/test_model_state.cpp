// Saving and restoring a model's state (the FMU's get/set/serialize, Python's pickling): a
// restored model continues to the last bit as the original did, and a state that does not fit is
// refused with a reason, leaving the model as it was.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "test_support.hpp"

namespace hm = hystlab::models;

namespace {
hm::EverettTable table_n(int n) {
  hm::SimplifiedSmaModel sma(hm::table1_parameters());
  return hm::identify_virtual(sma, hm::Grid::make(0.0, 4.0, n));
}

// The same continuation from a restored state as from the original, bit for bit, at a random cut.
void check_roll_back(hm::HysteresisModel& m, hm::HysteresisModel& fresh, std::uint64_t seed) {
  CAPTURE(seed);
  std::mt19937_64 rng(seed);
  const std::vector<double> path = hystlab::test::random_ramps(rng, -0.5, 4.5, 30, 0.07);
  const std::size_t cut = std::uniform_int_distribution<std::size_t>(1, path.size() - 2)(rng);
  CAPTURE(cut);
  const std::vector<double> head(path.begin(), path.begin() + static_cast<std::ptrdiff_t>(cut));
  const std::vector<double> tail(path.begin() + static_cast<std::ptrdiff_t>(cut), path.end());
  (void)hystlab::test::run_model(m, head);
  const std::vector<double> state = m.save_state();
  const std::vector<double> first = hystlab::test::run_model(m, tail);
  m.restore_state(state);  // roll back the same model
  const std::vector<double> again = hystlab::test::run_model(m, tail);
  fresh.restore_state(state);  // or carry the state to another instance
  const std::vector<double> moved = hystlab::test::run_model(fresh, tail);
  int same_again = 0, same_moved = 0;
  for (std::size_t k = 0; k < tail.size(); ++k) {
    same_again += first[k] == again[k] ? 1 : 0;  // exact: the same doubles
    same_moved += first[k] == moved[k] ? 1 : 0;
  }
  CHECK(same_again == static_cast<int>(tail.size()));
  CHECK(same_moved == static_cast<int>(tail.size()));
  CHECK(fresh.saturation_count() == m.saturation_count());
}
}  // namespace

TEST_CASE("a restored Preisach model continues bit for bit (seeded random paths and cuts)") {
  const hm::EverettTable t = table_n(12);
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    hm::PreisachModel m(t), fresh(t);
    check_roll_back(m, fresh, seed);
  }
}

TEST_CASE("a restored simplified SMA model continues bit for bit") {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    hm::SimplifiedSmaModel m(hm::table1_parameters()), fresh(hm::table1_parameters());
    check_roll_back(m, fresh, seed);
  }
}

TEST_CASE("a state that does not fit is refused with its reason, and the model keeps its own") {
  hm::PreisachModel m(table_n(12));
  for (const double x : {3.0, 1.0, 2.5, 1.5}) (void)m.step(x);
  const std::vector<double> own = m.save_state();
  const double before = m.peek(2.0);
  auto refused = [&](std::vector<double> s, const char* why) {
    CAPTURE(why);
    CHECK_THROWS_AS(m.restore_state(s), std::invalid_argument);
    CHECK(m.peek(2.0) == before);
    CHECK(m.save_state() == own);
  };
  refused({}, "empty");
  hm::SimplifiedSmaModel sma(hm::table1_parameters());
  refused(sma.save_state(), "another model's kind");
  std::vector<double> s = own;
  s.pop_back();
  refused(s, "one number short");
  s = own;
  s[1] = 1e9;
  refused(s, "too many turning points");
  s = own;
  s[9] = std::nan("");
  refused(s, "a NaN turning point");
  s = own;
  s[8] = 1.0;
  refused(s, "the first turning point is not the grid's lower end");
  hm::PreisachModel other(hm::EverettTable(hm::Grid::make(1.0, 5.0, 12)));
  CHECK_THROWS_WITH_AS(other.restore_state(own), doctest::Contains("another table"), std::invalid_argument);
  CHECK_THROWS_WITH_AS(sma.restore_state(own), doctest::Contains("simplified SMA"), std::invalid_argument);
}
