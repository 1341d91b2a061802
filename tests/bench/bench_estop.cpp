// The operator's e-stop, pressed over HTTP against a real hystlabd driving a simulated load frame
// (hystlab-sim over Modbus TCP, time scale 1) at 1 kHz, spread over the campaign's phases: just
// submitted, the preamble, ramping, dwelling at a node, paused, and the abort's safe ramp.
// For each press: the HTTP round trip (request to the answer, which comes only once the e-stop is
// written and seen in the controller's status word), the daemon's own time from taking the
// request to that confirmation, and the distance the frame moved after it (from the rig's latest
// sample read just before the request to where the frame rests, read 0.12 s after the end). Printed as p50/p99/max in ms
// and in sample periods (1 ms). Target: p99 <= 2 sample periods plus the HTTP round trip, whose
// own cost is measured in the same run (GET /api/status, the baseline). Asserts that every press
// was answered latched and confirmed, and each campaign ended.
#include <httplib.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "../support/daemon_process.hpp"

namespace {
using nlohmann::json;
double mono_now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

json get(httplib::Client& c, const std::string& path) {
  auto r = c.Get(path.c_str());
  if (!r || r->status != 200) throw std::runtime_error("GET " + path + " failed");
  return json::parse(r->body);
}

bool wait_for(const std::function<bool()>& pred, double seconds) {
  const double end = mono_now() + seconds;
  while (mono_now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

double quantile(std::vector<double> v, double f) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(f * static_cast<double>(v.size() - 1))];
}
}  // namespace

int main(int argc, char** argv) {
  const int presses = argc > 2 && std::string(argv[1]) == "--presses" ? std::atoi(argv[2]) : 1000;
  try {
    hystlab::test_support::DaemonProcess daemon(R"({"rigs": [{"name": "sim frame", "simulate": {"time_scale": 1, "noise_N": 0}}]})");
    httplib::Client c("127.0.0.1", daemon.port());
    c.set_read_timeout(10, 0);
    const json plan{{"kind", "fot"},       {"range_mm", {0, 1}},
                    {"subdivisions", 2},   {"ramp_rate_mm_s", 2.0},
                    {"dwell_s", 0.15},     {"sample_rate_hz", 1000},
                    {"validation", false}, {"limits", {{"displacement_mm", {-0.5, 1.5}}, {"force_N", 400}, {"rate_mm_s", 20}}}};
    const std::vector<std::string> phases{"just submitted", "preamble", "ramping", "dwelling", "paused", "safing"};
    const std::string rig = "/api/rigs/sim%20frame";
    auto phase_is = [&](const std::string& p, double min_x) {
      const json j = get(c, rig);
      return j.value("phase", "") == p && (min_x <= 0 || j["campaign"].get<long>() > 0);
    };
    if (!wait_for([&] { return get(c, rig)["state"] == "idle"; }, 60)) throw std::runtime_error("the rig never became idle");
    std::vector<double> http_ms, daemon_ms, moved_mm, baseline_ms;
    std::vector<std::vector<double>> by_phase(phases.size());
    int done = 0, failures = 0;
    // Reaching a phase races a short campaign (about 2 s): a host stall between seeing "ramping" and
    // the pause arriving can let the campaign finish first (stop 49's CI: press 10, "paused" not
    // reached, under a load average near 3). That is the benchmark missing its moment, not the
    // e-stop failing: the campaign is aborted and the press tried again on a new one, up to 5 times.
    auto submit = [&] {
      auto r = c.Post("/api/campaigns", json{{"plan", plan}}.dump(), "application/json");
      if (!r || r->status != 201) throw std::runtime_error("cannot submit a campaign: " + (r ? r->body : std::string("no answer")));
      return "/api/campaigns/" + std::to_string(json::parse(r->body)["id"].get<long>());
    };
    auto reach = [&](const std::string& phase, const std::string& camp) {
      if (phase == "just submitted") return true;
      if (phase == "preamble" || phase == "ramping" || phase == "dwelling") return wait_for([&] { return phase_is(phase, 0); }, 10);
      const bool paused = phase == "paused";
      if (!wait_for([&] { return phase_is(paused ? "ramping" : "dwelling", 0); }, 10)) return false;
      c.Post((camp + (paused ? "/pause" : "/abort")).c_str(), "", "application/json");
      return wait_for([&] { return phase_is(phase, 0); }, 10);
    };
    int missed = 0;
    for (int k = 0; k < presses; ++k) {
      const std::size_t ph = static_cast<std::size_t>(k) % phases.size();
      std::string camp = submit();
      for (int attempt = 1; !reach(phases[ph], camp); ++attempt) {
        if (attempt == 5) throw std::runtime_error("press " + std::to_string(k) + ": phase '" + phases[ph] + "' not reached in 5 campaigns");
        ++missed;
        c.Post((camp + "/abort").c_str(), "", "application/json");
        if (!wait_for([&] { return get(c, camp)["final"] == true && get(c, rig)["state"] == "idle"; }, 30)) throw std::runtime_error(camp + " never ended");
        camp = submit();
      }
      std::this_thread::sleep_for(std::chrono::microseconds(1000 * (k % 7)));  // anywhere in the phase's periods
      const double x_press = get(c, rig)["sample"].value("displacement_mm", NAN);
      const double t0 = mono_now();
      const auto a = c.Post((rig + "/estop").c_str(), "", "application/json");
      const double t1 = mono_now();
      // The HTTP round trip's own cost, right after, on the same connection kind (the baseline).
      const double b0 = mono_now();
      (void)c.Get("/api/status");
      baseline_ms.push_back((mono_now() - b0) * 1e3);
      if (!a || a->status != 200) {
        ++failures;
        std::fprintf(stderr, "press %d (%s): %s\n", k, phases[ph].c_str(), a ? a->body.c_str() : "no answer");
      } else {
        const json ans = json::parse(a->body);
        if (!(ans["latched"] == true && ans["confirmed"] == true)) ++failures;
        http_ms.push_back((t1 - t0) * 1e3);
        daemon_ms.push_back(ans["waited_ms"].get<double>());
        by_phase[ph].push_back((t1 - t0) * 1e3);
      }
      if (!wait_for([&] { return get(c, camp)["final"] == true; }, 30)) throw std::runtime_error(camp + " never ended");
      std::this_thread::sleep_for(std::chrono::milliseconds(120));  // idle reads: the snapshot shows where it rests
      const double rest = get(c, rig)["sample"].value("displacement_mm", NAN);
      if (std::isfinite(rest) && std::isfinite(x_press)) moved_mm.push_back(std::fabs(rest - x_press));
      const auto reset = c.Post((rig + "/reset").c_str(), "", "application/json");
      if (!reset || reset->status != 200) throw std::runtime_error("the reset after press " + std::to_string(k) + " failed");
      ++done;
    }
    const double period_ms = 1.0;
    std::printf("e-stop over %d presses at 1 kHz (hystlabd, hystlab-sim over Modbus TCP, time scale 1), %d not answered latched and confirmed\n", done,
                failures);
    std::printf("campaigns that ended before their press's phase was reached (tried again on a new one): %d\n", missed);
    std::printf("request -> answer (written, and seen in the status word), HTTP round trip: p50 %.2f ms, p99 %.2f ms, max %.2f ms\n", quantile(http_ms, 0.5),
                quantile(http_ms, 0.99), quantile(http_ms, 1.0));
    std::printf("the daemon's own time, request taken -> status word confirmed: p50 %.2f ms (%.1f periods), p99 %.2f ms (%.1f periods), max %.2f ms\n",
                quantile(daemon_ms, 0.5), quantile(daemon_ms, 0.5) / period_ms, quantile(daemon_ms, 0.99), quantile(daemon_ms, 0.99) / period_ms,
                quantile(daemon_ms, 1.0));
    std::printf("baseline: GET /api/status round trip p50 %.2f ms, p99 %.2f ms\n", quantile(baseline_ms, 0.5), quantile(baseline_ms, 0.99));
    const double target = 2 * period_ms + quantile(baseline_ms, 0.99);
    std::printf("target p99 <= 2 sample periods + the HTTP round trip = %.2f ms: %s (p99 %.2f ms)\n", target,
                quantile(http_ms, 0.99) <= target ? "met" : "NOT met", quantile(http_ms, 0.99));
    for (std::size_t p = 0; p < phases.size(); ++p)
      std::printf("  %-15s %3zu presses: p50 %.2f ms, p99 %.2f ms, max %.2f ms\n", phases[p].c_str(), by_phase[p].size(), quantile(by_phase[p], 0.5),
                  quantile(by_phase[p], 0.99), quantile(by_phase[p], 1.0));
    std::printf("distance moved after the e-stop (the sample read before the request -> rest), ramps at 2 mm/s: p99 %.4f mm, max %.4f mm\n",
                quantile(moved_mm, 0.99), quantile(moved_mm, 1.0));
    return failures == 0 && done == presses ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_estop: %s\n", e.what());
    return 1;
  }
}
