// The least-squares fit's time and peak memory on a long record (issue 13): the matrix-free fit
// (prior `auto`: both priors, each with 4-fold cross-validation over 7 smoothing weights, then the
// final fits and the σ probes) at n = 24, 48, 100 and 200, against the dense active-set fit it
// replaces (GCV, monotone prior; n <= 48), on the same record in the same run. Each fit runs in a
// child process, so its peak resident memory is its own (wait4's ru_maxrss).
// Target: n = 100 on 10^6 samples in under 10 s and 1 GiB.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "hystlab/models/lsq_fit.hpp"
#include "hystlab/models/preisach_fit.hpp"
#include "hystlab/models/simplified_sma.hpp"

using namespace hystlab::models;

namespace {

struct Measured {
  double seconds = 0.0, rms = 0.0, heldout = 0.0;
  long peak_kib = 0;
  bool ok = false;
};

struct Record {
  std::vector<double> x, y;
};

// Ramps between random turning points over 0..4 mm at 0.01 mm per sample, from the simplified SMA
// model (Table 1) with 0.2 N of noise: the random walk.
Record make_record(std::size_t samples) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> target(0.0, 4.0);
  std::normal_distribution<double> noise(0.0, 0.2);
  Record r;
  r.x.reserve(samples);
  double x = 0.0;
  while (r.x.size() < samples) {
    const double t = target(rng);
    const int steps = std::max(1, static_cast<int>(std::fabs(t - x) / 0.01));
    for (int k = 1; k <= steps && r.x.size() < samples; ++k) r.x.push_back(x + (t - x) * k / steps);
    x = t;
  }
  SimplifiedSmaModel m(table1_parameters());
  r.y.resize(samples);
  m.evaluate(r.x, r.y);
  for (double& v : r.y) v += noise(rng);
  return r;
}

// Runs fn in a child; the child writes its figures into a pipe, the parent reads its peak RSS.
template <class Fn>
Measured in_child(Fn fn) {
  int fd[2];
  if (pipe(fd) != 0) return {};
  const pid_t pid = fork();
  if (pid == 0) {
    close(fd[0]);
    Measured m = fn();
    m.ok = true;
    const ssize_t w = write(fd[1], &m, sizeof m);
    _exit(w == static_cast<ssize_t>(sizeof m) ? 0 : 1);
  }
  close(fd[1]);
  Measured m;
  const ssize_t got = read(fd[0], &m, sizeof m);
  close(fd[0]);
  int status = 0;
  rusage ru{};
  wait4(pid, &status, 0, &ru);
  if (got != static_cast<ssize_t>(sizeof m) || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return {};
  m.peak_kib = ru.ru_maxrss;
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t samples = 1'000'000;
  std::vector<int> sizes{24, 48, 100, 200};
  for (int a = 1; a + 1 < argc; a += 2) {
    if (std::strcmp(argv[a], "--samples") == 0) samples = std::strtoul(argv[a + 1], nullptr, 10);
    if (std::strcmp(argv[a], "--sizes") == 0) {
      sizes.clear();
      for (char* s = argv[a + 1]; *s != '\0';) {
        sizes.push_back(static_cast<int>(std::strtol(s, &s, 10)));
        if (*s == ',') ++s;
      }
    }
  }
  const Record rec = make_record(samples);
  const Measured idle = in_child([] { return Measured{}; });
  std::printf("least-squares fit on %zu samples (random walk over 0..4 mm, simplified model, 0.2 N noise)\n", samples);
  std::printf("%5s %28s %28s %10s\n", "n", "matrix-free auto: s / MiB", "dense monotone: s / MiB", "time ratio");
  int failures = 0;
  for (const int n : sizes) {
    const Grid g = Grid::make(0.0, 4.0, n);
    const Measured fresh = in_child([&] {
      const auto t0 = std::chrono::steady_clock::now();
      const PreisachFitResult r = fit_preisach(rec.x, rec.y, g);
      return Measured{std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), r.chosen.rms_residual, r.chosen.heldout_rms, 0, false};
    });
    Measured dense;
    if (n <= 48)
      dense = in_child([&] {
        const auto t0 = std::chrono::steady_clock::now();
        const LsqFitResult r = fit_preisach_lsq(rec.x, rec.y, g);
        return Measured{std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), r.rms_residual, 0.0, 0, false};
      });
    const double mib = static_cast<double>(fresh.peak_kib - idle.peak_kib) / 1024.0;
    char dense_text[64] = "not run (n > 48)", ratio[32] = "";
    if (dense.ok) {
      std::snprintf(dense_text, sizeof dense_text, "%.2f s / %.0f MiB", dense.seconds, static_cast<double>(dense.peak_kib - idle.peak_kib) / 1024.0);
      std::snprintf(ratio, sizeof ratio, "%.2fx", dense.seconds / fresh.seconds);
    }
    std::printf("%5d %19.2f s / %4.0f MiB %28s %10s   rms %.3f N (held-out %.3f N)%s\n", n, fresh.seconds, mib, dense_text, ratio, fresh.rms, fresh.heldout,
                dense.ok ? "" : "");
    // Agreement: the fit ran, and it is at least as close to the data as the monotone dense fit.
    if (!fresh.ok || !std::isfinite(fresh.rms)) ++failures;
    if (dense.ok && !(fresh.rms <= dense.rms * 1.001)) {
      std::printf("  FAIL: matrix-free rms %.4f N above the dense fit's %.4f N\n", fresh.rms, dense.rms);
      ++failures;
    }
    if (dense.ok) std::printf("      dense monotone rms %.3f N\n", dense.rms);
  }
  std::printf("(ratio: dense time / matrix-free time; memory: peak RSS of the fit's child process above an idle child)\n");
  return failures == 0 ? 0 : 1;
}
