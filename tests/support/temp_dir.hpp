#pragma once
// One temporary folder per test fixture, made under /tmp with a name that says whose it is
// (hystlab-<what>-XXXXXX: a folder left by a crashed test is recognisable), removed with
// everything in it when the fixture goes. Every test's fixture (stores, CLI work folders, daemon
// processes, FMU workspaces) keeps its files here.
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace hystlab::test_support {

class TempDir {
 public:
  explicit TempDir(const std::string& what = "test") {
    std::string tmpl = "/tmp/hystlab-" + what + "-XXXXXX";
    if (mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("cannot make a temporary folder " + tmpl);
    path_ = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const noexcept { return path_; }
  [[nodiscard]] std::filesystem::path operator/(const std::string& name) const { return path_ / name; }
  // A file of the folder, written whole.
  void write(const std::string& name, const std::string& text) const { std::ofstream(path_ / name) << text; }

 private:
  std::filesystem::path path_;
};

}  // namespace hystlab::test_support
