#pragma once
// The FMU tests' workspace: tables and parameters made by the CLI, exported as FMUs, and the
// CLI's own forces on an input, to compare with.
#include <doctest/doctest.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include "../support/build_paths.hpp"
#include "../support/temp_dir.hpp"
#include "fmu_importer.hpp"

namespace hystlab::test {
namespace fs = std::filesystem;
inline const std::string kCli = HYSTLAB_CLI;
inline constexpr fmi2ValueReference kX = 0, kF = 1, kXScale = 2, kXOffset = 3, kForceScale = 4, kSign = 5, kSaturations = 6;

struct Workspace {
  hystlab::test_support::TempDir tmp{"fmu"};
  fs::path dir = tmp.path();
  Workspace() {
    run("identify --model simplified --range 0,4 --subdivisions 12 -o T.json");
    run("identify --model simplified --range 0,4 --subdivisions 12 --refine 2,1 -o T2.json");  // a grid of its own
    std::ofstream(dir / "P.json") << R"({"model": "simplified-sma", "KA_N_per_mm": 40, "KM_N_per_mm": 150, "dtr_max_mm": 2.95,
      "C_N_per_degC": 5.7, "Mf0_degC": 12.7, "Ms0_degC": 17.9, "As0_degC": 17.9, "Af0_degC": 21.5, "T_degC": 25})";
  }
  std::string run(const std::string& args, int* status = nullptr) const {
    int st = 0;
    std::string out = shell("cd '" + dir.string() + "' && '" + kCli + "' " + args + " 2>&1", &st);
    if (status)
      *status = st;
    else if (st != 0)
      FAIL("hystlab " << args << ": " << out);
    return out;
  }
  fs::path fmu(const std::string& element, const std::string& name) const {
    const std::string flag = element[0] == 'P' ? "--params " : "--table ";
    run("export " + flag + element + " --format fmu -o " + name);
    return dir / name;
  }
};

// Seeded random ramps over [lo, hi], beyond the table's range at times.
inline std::vector<double> random_input(std::uint64_t seed, double lo, double hi, std::size_t n) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> x{0.0};
  while (x.size() < n) {
    const double a = x.back(), b = u(rng);
    const int steps = 1 + static_cast<int>(std::abs(b - a) / 0.05);
    for (int k = 1; k <= steps && x.size() < n; ++k) x.push_back(a + (b - a) * k / steps);
  }
  return x;
}

// `hystlab eval` on the same input: the forces, as the CLI prints them (shortest exact form).
inline std::vector<double> cli_forces(const Workspace& w, const std::string& model_args, const std::vector<double>& x) {
  std::ofstream csv(w.dir / "X.csv");
  csv << "displacement_mm\n";
  for (const double v : x) {
    char buf[32];
    csv << std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr) << "\n";
  }
  csv.close();
  int st = 0;  // stdout only: the CLI says on stderr how many inputs it clamped
  const std::string out = shell("cd '" + w.dir.string() + "' && '" + kCli + "' eval " + model_args + " --input X.csv 2>/dev/null", &st);
  REQUIRE(st == 0);
  std::vector<double> f;
  std::istringstream in(out);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) f.push_back(std::stod(line.substr(line.find(',') + 1)));
  return f;
}

// Initialized at x[0], then one doStep per further input; F read after each.
inline std::vector<double> run_fmu(const Fmu& f, fmi2Component c, const std::vector<double>& x, std::size_t from = 0, double t0 = 0.0) {
  std::vector<double> out;
  const double h = 1e-3;
  for (std::size_t k = from; k < x.size(); ++k) {
    REQUIRE(f.fmi2SetReal(c, &kX, 1, &x[k]) == fmi2OK);
    if (k > 0) REQUIRE(f.fmi2DoStep(c, t0 + static_cast<double>(k - 1) * h, h, fmi2True) == fmi2OK);
    if (k == 0) REQUIRE(f.fmi2ExitInitializationMode(c) == fmi2OK);
    double F = 0;
    REQUIRE(f.fmi2GetReal(c, &kF, 1, &F) == fmi2OK);
    out.push_back(F);
  }
  return out;
}

inline fmi2Component started(const Fmu& f, const fmi2CallbackFunctions& cb) {
  fmi2Component c = f.instantiate(cb);
  REQUIRE(c != nullptr);
  REQUIRE(f.fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK);
  REQUIRE(f.fmi2EnterInitializationMode(c) == fmi2OK);
  return c;
}

// A state's bytes, as fmi2SerializedFMUstateSize and fmi2SerializeFMUstate give them.
inline std::vector<fmi2Byte> serialized(const Fmu& f, fmi2Component c, fmi2FMUstate s) {
  std::size_t size = 0;
  REQUIRE(f.fmi2SerializedFMUstateSize(c, s, &size) == fmi2OK);
  std::vector<fmi2Byte> bytes(size);
  REQUIRE(f.fmi2SerializeFMUstate(c, s, bytes.data(), size) == fmi2OK);
  return bytes;
}

inline int exact_matches(const std::vector<double>& a, const std::vector<double>& b) {
  int n = 0;
  for (std::size_t k = 0; k < a.size() && k < b.size(); ++k) n += a[k] == b[k] ? 1 : 0;  // the same doubles
  return n;
}

}  // namespace hystlab::test
