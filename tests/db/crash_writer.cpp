// Helper for the crash test: writes samples through SampleWriter at about 20 k rows/s and prints
// the acknowledged sequence number every 10 ms. The test kills it with SIGKILL at a random moment.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "hystlab/db/sample_writer.hpp"

int main(int argc, char** argv) {
  if (argc < 3) return 2;
  const std::int64_t run = std::atoll(argv[2]);
  hystlab::db::SampleWriter w(argv[1]);
  std::int64_t seq = 0;
  auto next_print = std::chrono::steady_clock::now();
  for (;;) {
    for (int k = 0; k < 200; ++k, ++seq)
      w.try_push(hystlab::db::SampleRow{run, seq, static_cast<double>(seq) * 5e-5, 0.0, std::sin(static_cast<double>(seq) * 1e-3), 1.0, 1});
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (std::chrono::steady_clock::now() >= next_print) {
      std::printf("ack %lld\n", static_cast<long long>(w.stats().acknowledged_seq));
      std::fflush(stdout);
      next_print += std::chrono::milliseconds(10);
    }
  }
}
