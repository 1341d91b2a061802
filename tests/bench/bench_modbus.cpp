// Rig I/O speed: one poll (all sample registers) through ModbusRig against hystlab-sim, next to
// a bare libmodbus client/server pair doing the same read, interleaved in the same run; then a
// 1 kHz poll loop on absolute deadlines, reporting the period jitter.
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "../drivers/sim_process.hpp"
#include "hystlab/drivers/modbus_rig.hpp"
#include "hystlab/protocols/default_maps.hpp"

namespace {
using clock_type = std::chrono::steady_clock;

struct Stats {
  double per_s = 0, p50_us = 0, p99_us = 0, max_us = 0;
};

Stats stats(std::vector<double> us, double seconds) {
  std::sort(us.begin(), us.end());
  Stats s;
  s.per_s = static_cast<double>(us.size()) / seconds;
  s.p50_us = us[us.size() / 2];
  s.p99_us = us[us.size() * 99 / 100];
  s.max_us = us.back();
  return s;
}

// A bare libmodbus server on loopback in its own thread: 12 input registers, nothing else.
class BareServer {
 public:
  BareServer() {
    ctx_ = modbus_new_tcp("127.0.0.1", 0);
    listen_ = modbus_tcp_listen(ctx_, 1);
    sockaddr_in sa{};
    socklen_t len = sizeof sa;
    getsockname(listen_, reinterpret_cast<sockaddr*>(&sa), &len);
    port = ntohs(sa.sin_port);
    mapping_ = modbus_mapping_new(0, 0, 0, 16);
    thread_ = std::thread([this] {
      modbus_tcp_accept(ctx_, &listen_);
      std::uint8_t q[MODBUS_TCP_MAX_ADU_LENGTH];
      for (;;) {
        const int rc = modbus_receive(ctx_, q);
        if (rc > 0)
          modbus_reply(ctx_, q, rc, mapping_);
        else if (rc == -1)
          break;
      }
    });
  }
  ~BareServer() {
    thread_.join();
    modbus_mapping_free(mapping_);
    modbus_close(ctx_);
    modbus_free(ctx_);
  }
  int port = 0;

 private:
  modbus_t* ctx_;
  int listen_;
  modbus_mapping_t* mapping_;
  std::thread thread_;
};

Stats bare_polls(int n) {
  BareServer server;
  modbus_t* c = modbus_new_tcp("127.0.0.1", server.port);
  modbus_connect(c);
  std::uint16_t regs[12];
  std::vector<double> us;
  const auto start = clock_type::now();
  for (int k = 0; k < n; ++k) {
    const auto t0 = clock_type::now();
    if (modbus_read_input_registers(c, 0, 12, regs) != 12) std::fprintf(stderr, "bare read failed\n");
    us.push_back(std::chrono::duration<double, std::micro>(clock_type::now() - t0).count());
  }
  const double secs = std::chrono::duration<double>(clock_type::now() - start).count();
  modbus_close(c);
  modbus_free(c);
  return stats(us, secs);
}

Stats rig_polls(hystlab::drivers::ModbusRig& rig, int n, int& errors) {
  std::vector<double> us;
  hystlab::drivers::RigSample s;
  const auto start = clock_type::now();
  for (int k = 0; k < n; ++k) {
    const auto t0 = clock_type::now();
    if (rig.read_sample(hystlab::test::steady_now(), s)) ++errors;
    us.push_back(std::chrono::duration<double, std::micro>(clock_type::now() - t0).count());
  }
  return stats(us, std::chrono::duration<double>(clock_type::now() - start).count());
}

// What a lab acquisition thread does (hystlabd's, see daemon/realtime.hpp): a real-time FIFO
// priority and locked memory when allowed, and one CPU shared with the controller it polls, so a
// poll's wake-up is local (a cross-CPU wake-up on these VMs sometimes costs milliseconds).
std::string realtime_policy(pid_t controller) {
  sched_param sp{};
  sp.sched_priority = 50;
  const bool fifo = sched_setscheduler(0, SCHED_FIFO, &sp) == 0;
  const bool locked = mlockall(MCL_CURRENT | MCL_FUTURE) == 0;
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(static_cast<unsigned>(cpus - 1), &set);
  const bool pinned = cpus > 1 && sched_setaffinity(0, sizeof set, &set) == 0 && sched_setaffinity(controller, sizeof set, &set) == 0;
  return std::string(fifo ? "SCHED_FIFO 50" : "SCHED_OTHER (SCHED_FIFO not permitted)") + (locked ? ", memory locked" : "") +
         (pinned ? ", loop and simulator on CPU " + std::to_string(cpus - 1) : ", any CPU");
}

// A 1 kHz loop on absolute deadlines; with a rig it polls one sample per period. Without one
// it only sleeps: the baseline, which shows what the machine's scheduler alone adds.
void jitter_loop(hystlab::drivers::ModbusRig* rig, double seconds, const std::string& policy) {
  const long period_ns = 1'000'000;
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  std::vector<double> periods_us;
  timespec prev = next;
  long missed = 0, errors = 0;
  const long total = static_cast<long>(seconds * 1000);
  hystlab::drivers::RigSample s;
  for (long k = 0; k < total; ++k) {
    next.tv_nsec += period_ns;
    if (next.tv_nsec >= 1'000'000'000) next.tv_nsec -= 1'000'000'000, ++next.tv_sec;
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    const double late_us = static_cast<double>((now.tv_sec - next.tv_sec) * 1'000'000'000L + (now.tv_nsec - next.tv_nsec)) / 1e3;
    if (late_us > 1000) ++missed;  // a whole period late
    if (k > 0) periods_us.push_back(static_cast<double>((now.tv_sec - prev.tv_sec) * 1'000'000'000L + (now.tv_nsec - prev.tv_nsec)) / 1e3);
    prev = now;
    if (rig && rig->read_sample(hystlab::test::steady_now(), s)) ++errors;
  }
  std::vector<double> jitter;
  for (double p : periods_us) jitter.push_back(std::fabs(p - 1000.0));
  std::sort(jitter.begin(), jitter.end());
  std::printf(
      "%s for %.0f s: period jitter p50 %.1f us, p99 %.1f us, p99.9 %.1f us, max %.1f us; "
      "deadlines missed by a whole period: %ld; read errors: %ld; %s\n",
      rig ? "1 kHz poll loop (ModbusRig -> hystlab-sim)" : "baseline: 1 kHz sleep loop, no I/O", seconds, jitter[jitter.size() / 2],
      jitter[jitter.size() * 99 / 100], jitter[jitter.size() * 999 / 1000], jitter.back(), missed, errors, policy.c_str());
}
}  // namespace

int main(int argc, char** argv) {
  double jitter_seconds = 60;
  int polls = 5000, reps = 3;
  for (int k = 1; k + 1 < argc; k += 2) {
    if (!std::strcmp(argv[k], "--jitter-seconds")) jitter_seconds = std::atof(argv[k + 1]);
    if (!std::strcmp(argv[k], "--polls")) polls = std::atoi(argv[k + 1]);
  }
  // As hystlabd runs a supervised simulator: SCHED_FIFO just below the loop, on the loop's CPU.
  hystlab::test::SimProcess sim({"--port", "0", "--realtime", "49"});
  hystlab::drivers::ModbusRigConfig cfg;
  cfg.port = sim.modbus_port;
  cfg.map = hystlab::protocols::RegisterMap::from_json(hystlab::protocols::kDefaultLoadFrameMap);
  // Answers awaited 1.5 s: the CI VMs freeze whole for up to 0.7 s (both vCPUs at once), and a
  // read caught in one timed out at 50 ms with nothing wrong; this bench counts real errors.
  cfg.response_timeout_s = 1.5;
  hystlab::drivers::ModbusRig rig(cfg);
  if (rig.connect(hystlab::test::steady_now())) {
    std::printf("FAILED: cannot connect to hystlab-sim\n");
    return 1;
  }
  int errors = 0;
  std::vector<double> ratios;
  std::printf("%-26s %10s %9s %9s %9s\n", "poll (12 registers)", "polls/s", "p50 us", "p99 us", "max us");
  for (int r = 0; r < reps; ++r) {  // interleaved pairs: bare, then the rig, each rep
    const Stats b = bare_polls(polls);
    const Stats h = rig_polls(rig, polls, errors);
    std::printf("%-26s %10.0f %9.1f %9.1f %9.1f\n", "bare libmodbus pair", b.per_s, b.p50_us, b.p99_us, b.max_us);
    std::printf("%-26s %10.0f %9.1f %9.1f %9.1f\n", "ModbusRig -> hystlab-sim", h.per_s, h.p50_us, h.p99_us, h.max_us);
    ratios.push_back(h.per_s / b.per_s);
  }
  std::sort(ratios.begin(), ratios.end());
  const double median = ratios[ratios.size() / 2];  // issue 27 asks 90 % (an earlier issue 80 %)
  std::printf("rig/bare polls per second, median of %d interleaved pairs: %.0f %% (target >= 90 %%: %s); read errors: %d\n", reps, 100 * median,
              median >= 0.9 ? "met" : "NOT met", errors);
  if (jitter_seconds > 0) {
    const std::string policy = realtime_policy(sim.pid());
    jitter_loop(nullptr, jitter_seconds / 3, policy);
    jitter_loop(&rig, jitter_seconds, policy);
    std::printf("(target: p99 period jitter < 500 us; compare with the baseline, which no I/O code can beat)\n");
  }
  return errors == 0 ? 0 : 1;
}
