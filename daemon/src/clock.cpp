#include "hystlab/daemon/clock.hpp"

#include <chrono>
#include <cstdio>
#include <ctime>

#include "monotonic_clock.hpp"

namespace hystlab::daemon {

double SteadyClock::now() { return mono_now(); }
void SteadyClock::sleep_until(double t) { daemon::sleep_until(t); }

std::string now_iso() {
  const auto t = std::chrono::system_clock::now();
  const std::time_t s = std::chrono::system_clock::to_time_t(t);
  std::tm tm{};
  gmtime_r(&s, &tm);
  char buf[96];
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(t.time_since_epoch()).count() % 1000;
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec,
                static_cast<int>(ms));
  return buf;
}

}  // namespace hystlab::daemon
