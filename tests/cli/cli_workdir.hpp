#pragma once
// The CLI tests' working folder: the real binary run in a fresh temporary folder, its exit code,
// standard output and error; and the check of a refusal (one line naming the problem, exit 2).
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>
#include "../support/build_paths.hpp"
#include "../support/temp_dir.hpp"

namespace hystlab::test {
namespace fs = std::filesystem;

struct Result {
  int code = -1;
  std::string out, err;
};

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class Workdir {
 public:
  fs::path operator/(const std::string& name) const { return dir_ / name; }
  void write(const std::string& name, const std::string& text) const { std::ofstream(dir_ / name) << text; }
  Result run(const std::string& args) const { return run_raw("env -u HYSTLAB_DAEMON -u HYSTLAB_TOKEN '" + HYSTLAB_CLI + "' " + args); }
  // command: a shell command line (the CLI with an environment of its own).
  Result run_raw(const std::string& command) const {
    const std::string cmd = "cd '" + dir_.string() + "' && " + command + " > out.txt 2> err.txt < /dev/null";
    const int status = std::system(cmd.c_str());
    Result r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(dir_ / "out.txt");
    r.err = slurp(dir_ / "err.txt");
    return r;
  }

 private:
  hystlab::test_support::TempDir tmp_{"cli"};
  fs::path dir_ = tmp_.path();
};

// The values of column `col` of a CSV text (its header skipped), as the CLI writes them.
inline std::vector<double> csv_column(const std::string& csv, int col) {
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);
  std::vector<double> v;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string cell;
    for (int c = 0; c <= col; ++c) std::getline(ls, cell, ',');
    v.push_back(std::stod(cell));
  }
  return v;
}

// One error line naming the problem, exit code 2, nothing on stdout.
inline void check_error(const Result& r, const std::string& needle) {
  CAPTURE(r.err);
  CHECK(r.code == 2);
  CHECK(r.err.find(needle) != std::string::npos);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK(r.err.rfind("hystlab: error: ", 0) == 0);
}

}  // namespace hystlab::test
