// The FMU's fmi2DoStep throughput against the C API on the same table, in the same run (issue 15:
// target >= 0.8, raised to 0.9 by issue 27). One co-simulation step is what an importer does per input: fmi2SetReal(x),
// fmi2DoStep, fmi2GetReal(F); the C API's is hystlab_model_step. The FMU is the one the CLI
// writes (packaged here by the same library), unpacked with unzip and loaded with dlopen. Both
// run 10^6 random-ramp inputs, interleaved, best of 5; the forces are asserted identical.
#include <dlfcn.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "../../models/fmu/fmi2_functions.h"
#include "hystlab/fmu/fmu_archive.hpp"
#include "hystlab/hystlab.h"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/simplified_sma.hpp"

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {
std::vector<double> ramps(std::size_t n) {
  std::mt19937_64 rng(15);
  std::uniform_real_distribution<double> target(0.0, 4.0);
  std::vector<double> x{0.0};
  while (x.size() < n) {
    const double a = x.back(), b = target(rng);
    const int steps = 1 + static_cast<int>(std::fabs(b - a) / 0.01);
    for (int k = 1; k <= steps && x.size() < n; ++k) x.push_back(a + (b - a) * k / steps);
  }
  return x;
}

struct FmuApi {
  void* handle = nullptr;
  decltype(&fmi2Instantiate) instantiate = nullptr;
  decltype(&fmi2SetupExperiment) setup = nullptr;
  decltype(&fmi2EnterInitializationMode) enter = nullptr;
  decltype(&fmi2ExitInitializationMode) exit_init = nullptr;
  decltype(&fmi2SetReal) set_real = nullptr;
  decltype(&fmi2GetReal) get_real = nullptr;
  decltype(&fmi2DoStep) do_step = nullptr;
  decltype(&fmi2FreeInstance) free_instance = nullptr;
};

template <class F>
void lookup(void* h, const char* name, F& f) {
  f = reinterpret_cast<F>(dlsym(h, name));
  if (!f) std::fprintf(stderr, "bench_fmu: the FMU does not export %s\n", name), std::exit(1);
}

double run_fmu(const FmuApi& api, const std::string& guid, const std::string& uri, const std::vector<double>& x, std::vector<double>& out) {
  fmi2CallbackFunctions cb{};
  fmi2Component c = api.instantiate("bench", fmi2CoSimulation, guid.c_str(), uri.c_str(), &cb, fmi2False, fmi2False);
  if (!c) std::fprintf(stderr, "bench_fmu: instantiation refused\n"), std::exit(1);
  const fmi2ValueReference vx = 0, vf = 1;
  api.setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0);
  api.enter(c);
  api.set_real(c, &vx, 1, &x[0]);
  api.exit_init(c);
  api.get_real(c, &vf, 1, &out[0]);
  const auto t0 = Clock::now();
  double t = 0.0;
  for (std::size_t k = 1; k < x.size(); ++k) {
    api.set_real(c, &vx, 1, &x[k]);
    api.do_step(c, t, 1e-3, fmi2True);
    t += 1e-3;
    api.get_real(c, &vf, 1, &out[k]);
  }
  const double s = std::chrono::duration<double>(Clock::now() - t0).count();
  api.free_instance(c);
  return s;
}

// The FMU's calls without a step: fmi2SetReal of the input already taken and fmi2GetReal of the
// force (both on their fast paths), as many times as steps. What an importer's two extra calls
// cost beside the C API's one, whatever the model does.
double run_calls(const FmuApi& api, const std::string& guid, const std::string& uri, std::size_t n) {
  fmi2CallbackFunctions cb{};
  fmi2Component c = api.instantiate("bench", fmi2CoSimulation, guid.c_str(), uri.c_str(), &cb, fmi2False, fmi2False);
  if (!c) std::fprintf(stderr, "bench_fmu: instantiation refused\n"), std::exit(1);
  const fmi2ValueReference vx = 0, vf = 1;
  const double x0 = 1.0;
  double f = 0, acc = 0;
  api.setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0);
  api.enter(c);
  api.set_real(c, &vx, 1, &x0);
  api.exit_init(c);
  const auto t0 = Clock::now();
  for (std::size_t k = 1; k < n; ++k) {
    api.set_real(c, &vx, 1, &x0);
    api.get_real(c, &vf, 1, &f);
    acc += f;
  }
  const double s = std::chrono::duration<double>(Clock::now() - t0).count();
  api.free_instance(c);
  if (!(acc == acc)) std::printf("(non-finite force)\n");
  return s;
}

double run_capi(const std::string& json, const std::vector<double>& x, std::vector<double>& out) {
  hystlab_model* m = nullptr;
  if (hystlab_model_from_json(json.c_str(), &m) != HYSTLAB_OK) std::fprintf(stderr, "bench_fmu: %s\n", hystlab_last_error()), std::exit(1);
  hystlab_model_step(m, x[0], &out[0]);
  const auto t0 = Clock::now();
  for (std::size_t k = 1; k < x.size(); ++k) hystlab_model_step(m, x[k], &out[k]);
  const double s = std::chrono::duration<double>(Clock::now() - t0).count();
  hystlab_model_free(m);
  return s;
}
}  // namespace

int main(int argc, char** argv) {
  const std::size_t n = argc > 2 && std::string(argv[1]) == "--samples" ? std::stoul(argv[2]) : 1000000;
  namespace hm = hystlab::models;
  hm::SimplifiedSmaModel sma(hm::table1_parameters());
  const hm::EverettTable table = hm::identify_virtual(sma, hm::Grid::make(0.0, 4.0, 24));
  const std::string json = hm::table_to_json(table, hm::TableProvenance{"Table 1", "virtual-fot", "", "bench_fmu", {}}).dump();
  char tmpl[] = "/tmp/hystlab-bench-fmu-XXXXXX";
  const fs::path dir = mkdtemp(tmpl);
  std::ofstream(dir / "T.fmu", std::ios::binary) << hystlab::fmu::fmu_archive(json);
  if (std::system(("unzip -q '" + (dir / "T.fmu").string() + "' -d '" + (dir / "T").string() + "'").c_str()) != 0) return 1;
  FmuApi api;
  api.handle = dlopen((dir / "T/binaries/linux64/hystlab_element.so").c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!api.handle) return std::fprintf(stderr, "bench_fmu: %s\n", dlerror()), 1;
  lookup(api.handle, "fmi2Instantiate", api.instantiate);
  lookup(api.handle, "fmi2SetupExperiment", api.setup);
  lookup(api.handle, "fmi2EnterInitializationMode", api.enter);
  lookup(api.handle, "fmi2ExitInitializationMode", api.exit_init);
  lookup(api.handle, "fmi2SetReal", api.set_real);
  lookup(api.handle, "fmi2GetReal", api.get_real);
  lookup(api.handle, "fmi2DoStep", api.do_step);
  lookup(api.handle, "fmi2FreeInstance", api.free_instance);
  std::ifstream md(dir / "T/modelDescription.xml");
  const std::string xml((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  const auto g = xml.find("guid=\"") + 6;
  const std::string guid = xml.substr(g, xml.find('"', g) - g), uri = "file://" + (dir / "T/resources").string();

  const std::vector<double> x = ramps(n);
  std::vector<double> f_fmu(n), f_capi(n);
  double best_fmu = 1e9, best_capi = 1e9, best_calls = 1e9;
  for (int rep = 0; rep < 5; ++rep) {  // interleaved: a slow spell of the machine hits both
    best_fmu = std::min(best_fmu, run_fmu(api, guid, uri, x, f_fmu));
    best_capi = std::min(best_capi, run_capi(json, x, f_capi));
    best_calls = std::min(best_calls, run_calls(api, guid, uri, n));
  }
  std::size_t same = 0;
  for (std::size_t k = 0; k < n; ++k) same += f_fmu[k] == f_capi[k] ? 1U : 0U;
  dlclose(api.handle);
  fs::remove_all(dir);
  std::printf("bench_fmu: %zu random-ramp inputs on an n = 24 table, best of 5, interleaved\n", n);
  std::printf("  C API hystlab_model_step:               %7.1f ns/step  %6.2f M steps/s\n", 1e9 * best_capi / double(n - 1), double(n - 1) / best_capi / 1e6);
  std::printf("  FMU fmi2SetReal + fmi2DoStep + GetReal: %7.1f ns/step  %6.2f M steps/s\n", 1e9 * best_fmu / double(n - 1), double(n - 1) / best_fmu / 1e6);
  // Issue 27 raised the target from 0.8 (issue 15) to 0.9. The C API steps a table inlined since
  // (no virtual call): the FMU's three calls through the importer's pointers weigh more beside it.
  const double ratio = best_capi / best_fmu;
  std::printf("  ratio FMU / C API throughput: %.2f (target >= 0.9, issue 27: %s)\n", ratio, ratio >= 0.9 ? "met" : "NOT met");
  // What remains: the FMU's step minus its two extra calls is the C API's step plus fmi2DoStep's
  // own checks (FMI's mode, the step size, the input's finiteness after scale and offset).
  const double calls_ns = 1e9 * best_calls / double(n - 1), capi_ns = 1e9 * best_capi / double(n - 1), fmu_ns = 1e9 * best_fmu / double(n - 1);
  std::printf("  of which fmi2SetReal + fmi2GetReal alone (fast paths, no step): %.1f ns; fmi2DoStep beyond the C API's step: %.1f ns\n", calls_ns,
              fmu_ns - calls_ns - capi_ns);
  std::printf("  the C API's step plus those two calls alone: ratio %.2f (the most three calls can reach here)\n", capi_ns / (capi_ns + calls_ns));
  std::printf("  identical forces: %zu of %zu\n", same, n);
  return same == n ? 0 : 1;
}
