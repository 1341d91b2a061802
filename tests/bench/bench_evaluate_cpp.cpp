// The C++ side of bench_python.py: a table evaluated on an input file by PreisachModel::step in a
// plain loop (what a C++ caller of the library writes), best of several repetitions from rest.
// usage: bench_evaluate_cpp TABLE.json INPUT.f64 OUTPUT.f64 [REPETITIONS]
//   INPUT.f64 / OUTPUT.f64: native doubles, back to back. Prints "cpp_ns_per_sample <best>".
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <vector>

#include "hystlab/models/formats.hpp"
#include "hystlab/models/preisach_model.hpp"

namespace {

std::string read_all(const char* path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(std::string("cannot open '") + path + "'");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::cerr << "usage: bench_evaluate_cpp TABLE.json INPUT.f64 OUTPUT.f64 [REPETITIONS]\n";
    return 2;
  }
  try {
    hystlab::models::PreisachModel model(hystlab::models::table_from_json(read_all(argv[1])).table);
    const std::string raw = read_all(argv[2]);
    std::vector<double> x(raw.size() / sizeof(double)), f(x.size());
    std::copy(raw.data(), raw.data() + x.size() * sizeof(double), reinterpret_cast<char*>(x.data()));
    const int reps = argc > 4 ? std::atoi(argv[4]) : 7;
    double best = std::numeric_limits<double>::infinity();
    for (int r = 0; r < reps; ++r) {
      model.reset();
      const auto t0 = std::chrono::steady_clock::now();
      for (std::size_t k = 0; k < x.size(); ++k) f[k] = model.step(x[k]);
      const auto t1 = std::chrono::steady_clock::now();
      best = std::min(best, std::chrono::duration<double, std::nano>(t1 - t0).count() / static_cast<double>(x.size()));
    }
    std::ofstream out(argv[3], std::ios::binary);
    out.write(reinterpret_cast<const char*>(f.data()), static_cast<std::streamsize>(f.size() * sizeof(double)));
    if (!out) throw std::runtime_error(std::string("cannot write '") + argv[3] + "'");
    std::printf("cpp_ns_per_sample %.3f\n", best);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bench_evaluate_cpp: " << e.what() << "\n";
    return 2;
  }
}
