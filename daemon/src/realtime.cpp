#include "hystlab/daemon/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <cstring>

namespace hystlab::daemon {
namespace {
cpu_set_t only(int cpu) noexcept {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(static_cast<unsigned>(cpu), &set);
  return set;
}
}  // namespace

int resolve_cpu(int cpu) noexcept {
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  if (cpu == AcquisitionSettings::kAnyCpu || online <= 1) return -1;
  if (cpu == AcquisitionSettings::kLastCpu) return static_cast<int>(online - 1);
  return cpu >= 0 && cpu < online ? cpu : -1;
}

std::string enter_acquisition_thread(const AcquisitionSettings& s) noexcept {
  std::string got;
  if (s.priority > 0) {
    sched_param p{};
    p.sched_priority = s.priority;
    const int err = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);
    got = err ? std::string("normal priority (SCHED_FIFO refused: ") + std::strerror(err) + ")"
              : "real-time priority (SCHED_FIFO " + std::to_string(s.priority) + ")";
  } else {
    got = "normal priority";
  }
  if (const int cpu = resolve_cpu(s.cpu); cpu >= 0) {
    const cpu_set_t set = only(cpu);
    const int err = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
    got += err ? std::string(", on any CPU (pinning refused: ") + std::strerror(err) + ")" : ", on CPU " + std::to_string(cpu);
  } else {
    got += ", on any CPU";
  }
  return got;
}

bool avoid_cpu(int cpu) noexcept {
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  if (online <= 1) return false;
  cpu_set_t set;
  CPU_ZERO(&set);
  for (long k = 0; k < online && k < CPU_SETSIZE; ++k)
    if (k != cpu) CPU_SET(static_cast<unsigned>(k), &set);
  return pthread_setaffinity_np(pthread_self(), sizeof set, &set) == 0;
}

bool pin_process(pid_t pid, int cpu) noexcept {
  if (cpu < 0) return false;
  const cpu_set_t set = only(cpu);
  return sched_setaffinity(pid, sizeof set, &set) == 0;
}

}  // namespace hystlab::daemon
