#pragma once
// A minimal FMI 2.0 co-simulation importer, the tests' own: unpack an .fmu with unzip, read what
// modelDescription.xml says with xmllint, dlopen the binary it names and look up every function.
#include <dlfcn.h>

#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "../../models/fmu/fmi2_functions.h"

namespace hystlab::test {

// Runs a shell command; its standard output, and its exit status in *status.
inline std::string shell(const std::string& cmd, int* status = nullptr) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) throw std::runtime_error("popen failed: " + cmd);
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  const int st = pclose(p);
  if (status) *status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return out;
}

// What the importer saw of the last message the FMU logged (the logger is C-variadic; the FMU
// always passes "%s" and one string).
struct LogBook {
  std::vector<std::string> messages;
  std::vector<fmi2Status> statuses;
};

extern "C" inline void test_fmu_logger(fmi2ComponentEnvironment env, fmi2String, fmi2Status status, fmi2String, fmi2String fmt, ...) {
  auto* book = static_cast<LogBook*>(env);
  char buf[2048];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  book->messages.emplace_back(buf);
  book->statuses.push_back(status);
}

struct Fmu {
  std::filesystem::path dir;
  std::string guid, identifier;
  void* handle = nullptr;
#define HYSTLAB_TEST_FMI2_POINTER(name) decltype(&::name) name = nullptr;
  HYSTLAB_FMI2_CS_FUNCTIONS(HYSTLAB_TEST_FMI2_POINTER)
#undef HYSTLAB_TEST_FMI2_POINTER

  std::string xpath(const std::string& expr) const {
    std::string v = shell("xmllint --xpath '" + expr + "' '" + (dir / "modelDescription.xml").string() + "' 2>/dev/null");
    while (!v.empty() && (v.back() == '\n' || v.back() == ' ')) v.pop_back();
    return v;
  }

  // Unpacks into dir and loads; throws naming what is missing.
  Fmu(const std::filesystem::path& fmu_file, const std::filesystem::path& into) : dir(into) {
    std::filesystem::create_directories(dir);
    int st = 0;
    shell("unzip -q -o '" + fmu_file.string() + "' -d '" + dir.string() + "' 2>&1", &st);
    if (st != 0) throw std::runtime_error("unzip failed on " + fmu_file.string());
    guid = xpath("string(/fmiModelDescription/@guid)");
    identifier = xpath("string(/fmiModelDescription/CoSimulation/@modelIdentifier)");
    const auto so = dir / "binaries" / "linux64" / (identifier + ".so");
    handle = dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) throw std::runtime_error(std::string("dlopen: ") + dlerror());
#define HYSTLAB_TEST_FMI2_LOOKUP(name)                              \
  name = reinterpret_cast<decltype(&::name)>(dlsym(handle, #name)); \
  if (!name) throw std::runtime_error("the FMU's binary does not export " #name);
    HYSTLAB_FMI2_CS_FUNCTIONS(HYSTLAB_TEST_FMI2_LOOKUP)
#undef HYSTLAB_TEST_FMI2_LOOKUP
  }
  Fmu(const Fmu&) = delete;
  Fmu& operator=(const Fmu&) = delete;
  ~Fmu() {
    if (handle) dlclose(handle);
  }

  std::string resource_uri() const { return "file://" + (dir / "resources").string(); }

  // An instance (nullptr, with the reason logged, when refused).
  fmi2Component instantiate(const fmi2CallbackFunctions& cb, const std::string& name = "test") const {
    return fmi2Instantiate(name.c_str(), fmi2CoSimulation, guid.c_str(), resource_uri().c_str(), &cb, fmi2False, fmi2False);
  }
};

inline fmi2CallbackFunctions callbacks(LogBook& book) { return fmi2CallbackFunctions{test_fmu_logger, nullptr, nullptr, nullptr, &book}; }

}  // namespace hystlab::test
