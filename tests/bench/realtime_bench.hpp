#pragma once
// A rig's acquisition as hystlabd sets it up (daemon/realtime.hpp): the simulator on the
// acquisition's CPU one priority below it, a database file with its writer thread started at
// normal priority off that CPU, and the calling thread made the acquisition thread (SCHED_FIFO
// when allowed, pinned). For the benchmarks that run a campaign in real time.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "../drivers/sim_process.hpp"
#include "hystlab/daemon/realtime.hpp"
#include "hystlab/db/sample_writer.hpp"

namespace hystlab::test {

struct RealtimeBench {
  explicit RealtimeBench(std::vector<std::string> sim_args)
      : sim(with_priority(std::move(sim_args))), dir(temp_dir()), path((dir / "hystlab.db").string()), store(path) {
    if (!daemon::pin_process(sim.pid(), daemon::resolve_cpu(settings.cpu))) std::printf("the simulator is not pinned\n");
    const bool moved = daemon::avoid_cpu(daemon::resolve_cpu(settings.cpu));
    writer = std::make_unique<db::SampleWriter>(path);
    if (moved) (void)daemon::avoid_cpu(-1);
    std::printf("this thread: %s\n", daemon::enter_acquisition_thread(settings).c_str());
  }
  ~RealtimeBench() {
    writer.reset();
    std::filesystem::remove_all(dir);
  }
  static inline const daemon::AcquisitionSettings settings{};  // the daemon's defaults
  SimProcess sim;
  std::filesystem::path dir;
  std::string path;
  db::Store store;
  std::unique_ptr<db::SampleWriter> writer;

 private:
  static std::vector<std::string> with_priority(std::vector<std::string> a) {
    a.push_back("--realtime");
    a.push_back(std::to_string(settings.priority - 1));
    return a;
  }
  static std::filesystem::path temp_dir() {
    char tmpl[] = "/tmp/hystlab-bench-XXXXXX";
    return mkdtemp(tmpl);
  }
};

}  // namespace hystlab::test
