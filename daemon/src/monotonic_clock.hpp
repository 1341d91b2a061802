#pragma once
// The runners' clock: monotonic seconds, wall-clock seconds for the run's anchor, and sleeping
// until an absolute monotonic deadline (no drift across periods).
#include <time.h>

#include <chrono>

namespace hystlab::daemon {

inline double mono_now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

inline double wall_now() { return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count(); }

inline void sleep_until(double t) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t);
  ts.tv_nsec = static_cast<long>((t - static_cast<double>(ts.tv_sec)) * 1e9);
  clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
}

}  // namespace hystlab::daemon
