// Preisach evaluation speed, in the same run: the library's step (PreisachModel) against the bare
// cached-Everett loop (bare_everett.hpp), interleaved on the same inputs, and against a
// brute-force relay grid of the same n. Prints steps/s and the median of per-repetition ratios,
// and how the step's cost grows with the stack's depth, with n and with the number of models
// stepped together.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "bare_against_library.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/relay_grid.hpp"

using namespace hystlab::models;

namespace {
constexpr int kSizes[] = {12, 48, 200};
constexpr std::size_t kSteps = 1'000'000;

std::vector<Relay> relays_for(int n) {
  std::mt19937_64 rng(static_cast<std::uint64_t>(n));
  std::uniform_real_distribution<double> frac(0.05, 0.95), w(0.1, 1.1);
  const Grid g = Grid::make(0.0, 4.0, n);
  std::vector<Relay> r;
  for (int p = 1; p <= n; ++p)
    for (int q = 1; q <= p; ++q) {
      double a = g.node(p - 1) + frac(rng) * g.step(), b = g.node(q - 1) + frac(rng) * g.step();
      if (q == p && b > a) std::swap(a, b);
      r.push_back(Relay{a, b, w(rng)});
    }
  return r;
}

const std::vector<double>& uniform_input() {
  static const std::vector<double> v = [] {
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(0.0, 4.0);
    std::vector<double> x(kSteps);
    for (double& e : x) e = u(rng);
    return x;
  }();
  return v;
}

// Relays and table agree exactly on grid-node inputs; checked before anything is timed.
bool agreement_ok() {
  bool ok = true;
  for (int n : kSizes) {
    const Grid g = Grid::make(0.0, 4.0, n);
    RelayGrid relays(relays_for(n));
    PreisachModel model(relays.everett_table(g));
    std::mt19937_64 rng(7);
    std::uniform_int_distribution<int> pick(0, n);
    double worst = 0.0, scale = 1e-3;
    for (int k = 0; k < 20000; ++k) {
      const double x = g.node(pick(rng));
      const double a = relays.step(x), b = model.step(x);
      worst = std::max(worst, std::fabs(a - b));
      scale = std::max(scale, std::fabs(a));
    }
    std::printf("agreement n = %3d: max |everett - relays| / max |f| = %.2e\n", n, worst / scale);
    ok = ok && worst / scale < 1e-9;
  }
  return ok;
}

void BM_Everett(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  PreisachModel model(RelayGrid(relays_for(n)).everett_table(Grid::make(0.0, 4.0, n)));
  const auto& x = uniform_input();
  for (auto _ : state) {
    model.reset();
    double acc = 0.0;
    for (double v : x) acc += model.step(v);
    benchmark::DoNotOptimize(acc);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(x.size()));
}

void BM_RelayGrid(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  RelayGrid relays(relays_for(n));
  // The relay grid's cost per step does not depend on the input; fewer steps keep n = 200 short.
  const std::size_t steps = n >= 200 ? 20'000 : n >= 48 ? 100'000 : kSteps;
  const auto& x = uniform_input();
  for (auto _ : state) {
    relays.reset();
    double acc = 0.0;
    for (std::size_t k = 0; k < steps; ++k) acc += relays.step(x[k]);
    benchmark::DoNotOptimize(acc);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(steps));
}

BENCHMARK(BM_Everett)->Arg(12)->Arg(48)->Arg(200)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RelayGrid)->Arg(12)->Arg(48)->Arg(200)->Unit(benchmark::kMillisecond);

// Keeps every repetition's rate, in run order, to pair them for the ratios.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs)
      if (r.run_type == Run::RT_Iteration) {
        const auto it = r.counters.find("items_per_second");
        if (it != r.counters.end()) rates[r.benchmark_name()].push_back(it->second.value);
      }
  }
  std::map<std::string, std::vector<double>> rates;
};

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
}  // namespace

int main(int argc, char** argv) {
  if (!agreement_ok()) {
    std::printf("FAILED: the Everett evaluation disagrees with the relay grid\n");
    return 1;
  }
  if (!hystlab::bench::against_bare()) return 1;
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  std::printf("\nPreisach evaluation, %zu random steps (uniform on the range):\n", kSteps);
  std::printf("%5s %18s %18s %14s %12s\n", "n", "everett steps/s", "relays steps/s", "ratio (median)", "40 M target");
  for (int n : kSizes) {
    const auto& e = reporter.rates["BM_Everett/" + std::to_string(n)];
    const auto& r = reporter.rates["BM_RelayGrid/" + std::to_string(n)];
    std::vector<double> ratios;
    for (std::size_t k = 0; k < std::min(e.size(), r.size()); ++k) ratios.push_back(e[k] / r[k]);
    const double best = e.empty() ? 0.0 : *std::max_element(e.begin(), e.end());
    std::printf("%5d %16.2f M %16.3f M %13.1fx %12s\n", n, median(e) / 1e6, median(r) / 1e6, median(ratios), best >= 40e6 ? "met" : "NOT met");
  }
  std::printf(
      "(ratio: median over repetitions of everett/relays, each pair from the same repetition; "
      "target at n = 200: >= 500x)\n");
  return 0;
}
