#include "hystlab/daemon/clock.hpp"

#include "monotonic_clock.hpp"

namespace hystlab::daemon {

double SteadyClock::now() { return mono_now(); }
void SteadyClock::sleep_until(double t) { daemon::sleep_until(t); }

}  // namespace hystlab::daemon
