// wrk (Debian's) against hystlabd's GET /api/status for 10 s, next to a bare cpp-httplib server
// answering a JSON document of the same size, with the same transport settings (TCP_NODELAY, a
// pool sized like the daemon's, bounded keep-alive), in the same run: the ratio is what the
// daemon's own work per request costs. Target: at least 50 % of the bare server's requests/s.
#include <httplib.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>

#include "../support/daemon_process.hpp"

namespace {
struct WrkResult {
  double rps = 0, p50_ms = 0, p99_ms = 0;
  long errors = 0;
};

double to_ms(const std::string& v) {  // wrk prints 512.00us, 1.20ms, 1.01s
  const double x = std::stod(v);
  if (v.find("us") != std::string::npos) return x / 1000;
  if (v.find("ms") != std::string::npos) return x;
  return x * 1000;
}

WrkResult run_wrk(int port, int seconds) {
  const std::string cmd = "wrk -t2 -c32 -d" + std::to_string(seconds) + "s --latency http://127.0.0.1:" + std::to_string(port) + "/api/status 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) throw std::runtime_error("cannot run wrk");
  WrkResult r;
  char line[512];
  while (std::fgets(line, sizeof line, p)) {
    std::string s(line);
    char unit[32];
    double v = 0;
    if (std::sscanf(line, "Requests/sec: %lf", &v) == 1) r.rps = v;
    if (std::sscanf(line, " 50%% %31s", unit) == 1) r.p50_ms = to_ms(unit);
    if (std::sscanf(line, " 99%% %31s", unit) == 1) r.p99_ms = to_ms(unit);
    if (s.find("Socket errors") != std::string::npos || s.find("Non-2xx") != std::string::npos) {
      std::fputs(line, stdout);
      r.errors += 1;
    }
  }
  if (pclose(p) != 0 || r.rps == 0) throw std::runtime_error("wrk failed (is it installed? apt install wrk)");
  return r;
}
}  // namespace

int main(int argc, char** argv) {
  const int seconds = argc > 2 && std::string(argv[1]) == "--seconds" ? std::atoi(argv[2]) : 10;
  try {
    hystlab::test_support::DaemonProcess daemon(R"({"rigs": [{"name": "sim frame", "simulate": {"time_scale": 1}}]})");
    httplib::Client c("127.0.0.1", daemon.port());
    auto status = c.Get("/api/status");
    if (!status || status->status != 200) throw std::runtime_error("hystlabd does not answer /api/status");
    const std::size_t size = status->body.size();

    // The bare server: the same JSON size, the same transport settings as hystlabd's.
    httplib::Server bare;
    bare.set_tcp_nodelay(true);
    bare.new_task_queue = [] { return new httplib::ThreadPool(64 + 16); };
    bare.set_keep_alive_max_count(100);
    const std::string body = "{\"pad\":\"" + std::string(size > 10 ? size - 10 : 0, 'x') + "\"}";
    bare.Get("/api/status", [&body](const httplib::Request&, httplib::Response& res) { res.set_content(body, "application/json"); });
    const int bare_port = bare.bind_to_any_port("127.0.0.1");
    std::thread t([&bare] { bare.listen_after_bind(); });

    const WrkResult b = run_wrk(bare_port, seconds);
    const WrkResult d = run_wrk(daemon.port(), seconds);
    bare.stop();
    t.join();
    std::printf("bare cpp-httplib (%zu-byte JSON): %.0f requests/s, latency p50 %.3f ms, p99 %.3f ms\n", body.size(), b.rps, b.p50_ms, b.p99_ms);
    std::printf("hystlabd GET /api/status (%zu bytes): %.0f requests/s, latency p50 %.3f ms, p99 %.3f ms\n", size, d.rps, d.p50_ms, d.p99_ms);
    const double ratio = d.rps / b.rps;  // issue 27 asks 0.95 (an earlier issue 0.5)
    std::printf("ratio hystlabd / bare: %.2f (target >= 0.95: %s)%s\n", ratio, ratio >= 0.95 ? "met" : "NOT met",
                b.errors + d.errors ? "; wrk reported errors" : "");
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_http: %s\n", e.what());
    return 1;
  }
}
