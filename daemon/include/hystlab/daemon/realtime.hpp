#pragma once
// How an acquisition thread runs: a SCHED_FIFO priority, and one CPU shared with the simulated
// controller it polls. Sharing the CPU makes each poll's wake-up local: on the 2-CPU VMs here a
// cross-CPU wake-up sometimes costs milliseconds (a 1 kHz Modbus poll loop measured p99 period
// jitter 400-830 us unpinned, 120-175 us pinned; tests/bench/bench_modbus).
#include <sys/types.h>

#include <string>

namespace hystlab::daemon {

struct AcquisitionSettings {
  static constexpr int kLastCpu = -1;  // the machine's last CPU (the first one takes most interrupts)
  static constexpr int kAnyCpu = -2;   // no pinning
  int priority = 20;                   // SCHED_FIFO priority; 0: normal scheduling
  int cpu = kLastCpu;
};

// The CPU index the setting names on this machine, or -1 for none (kAnyCpu, a one-CPU machine,
// or a CPU that is not there).
[[nodiscard]] int resolve_cpu(int cpu) noexcept;

// Applies the settings to the calling thread, as far as the system allows (SCHED_FIFO needs
// CAP_SYS_NICE or an rtprio limit; pinning needs nothing). Returns what was granted, for the log.
std::string enter_acquisition_thread(const AcquisitionSettings& s) noexcept;

// Keeps the calling thread off the CPU (when there is another), or lets it run anywhere again
// (cpu < 0). For threads whose system calls would delay the acquisition's wake-ups there (the
// kernel here does not preempt system calls): the writer, event streams. A thread started
// meanwhile inherits it. (Keeping every HTTP thread off it cost a third of the HTTP throughput
// on 2 CPUs.)
bool avoid_cpu(int cpu) noexcept;

// Pins a process (a supervised simulator) to the CPU; false if refused or cpu < 0.
bool pin_process(pid_t pid, int cpu) noexcept;

}  // namespace hystlab::daemon
