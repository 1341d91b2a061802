// wrk (Debian's) against hystlabd's GET /api/status, next to a bare cpp-httplib server answering a
// JSON document of the same size, with the same transport settings (TCP_NODELAY, a pool sized like
// the daemon's, bounded keep-alive), in the same run: the ratio is what the daemon's own work per
// request costs. Six rounds of 3 s each, the two servers in turn (each order in three), and the
// median of the rounds' ratios: one 10 s run of each read 0.90 to 1.03 over the last stops' clean-
// clone runs (issue 27), where a slow spell of the shared machine fell on one side only.
// Target (issue 27): at least 0.95 of the bare server's requests/s.
// (Not the request threads' lower priority, nice 5: against a bare server at nice 5 in the same
// rounds hystlabd read 0.79 to 1.00, as against one at nice 0; stop 38. What it was, by perf:
// the page's mount point at "/", which cpp-httplib tries before any route, so every API request
// stat()ed a file that is not there, 4.6 % of the daemon's CPU; the page is now a route after the
// API's (web/src/page_route.cpp), and the median went from 0.94 to 0.98 here, stop 39. The four
// security headers, tried as a third server in the same rounds, cost nothing measurable.)
#include <httplib.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

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
  const int seconds = argc > 2 && std::string(argv[1]) == "--seconds" ? std::atoi(argv[2]) : 3;
  constexpr int kRounds = 6;  // even: as many rounds with the bare server first as with hystlabd first
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

    std::vector<double> ratios;
    long errors = 0;
    std::printf("bench_http: wrk -t2 -c32, %d rounds of %d s a server, the order alternating\n", kRounds, seconds);
    for (int r = 0; r < kRounds; ++r) {
      WrkResult b, d;
      if (r % 2 == 0)
        b = run_wrk(bare_port, seconds), d = run_wrk(daemon.port(), seconds);
      else
        d = run_wrk(daemon.port(), seconds), b = run_wrk(bare_port, seconds);
      ratios.push_back(d.rps / b.rps);
      errors += b.errors + d.errors;
      std::printf(
          "  round %d: bare cpp-httplib (%zu-byte JSON) %.0f requests/s (p50 %.3f ms, p99 %.3f ms); hystlabd GET /api/status (%zu bytes) %.0f "
          "requests/s (p50 %.3f ms, p99 %.3f ms); ratio %.3f\n",
          r + 1, body.size(), b.rps, b.p50_ms, b.p99_ms, size, d.rps, d.p50_ms, d.p99_ms, ratios.back());
    }
    bare.stop();
    t.join();
    std::sort(ratios.begin(), ratios.end());
    const double ratio = 0.5 * (ratios[kRounds / 2 - 1] + ratios[kRounds / 2]);  // the median; issue 27 asks 0.95 (an earlier issue 0.5)
    std::printf("ratio hystlabd / bare, median of %d rounds: %.2f (rounds %.2f to %.2f; target >= 0.95: %s)%s\n", kRounds, ratio, ratios.front(), ratios.back(),
                ratio >= 0.95 ? "met" : "NOT met", errors ? "; wrk reported errors" : "");
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_http: %s\n", e.what());
    return 1;
  }
}
