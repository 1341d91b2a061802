#pragma once
// The acquisition loop's periods (acquisition_tick.cpp), for the run around them
// (acquisition_run.cpp). Internal to the daemon library.
#include "acquisition_loop.hpp"
#include "hystlab/daemon/supervisor.hpp"
#include "hystlab/drivers/rig.hpp"

namespace hystlab::daemon {

// A sample's status, as the supervisor reads it.
StatusView view_of(const drivers::RigSample& s);
StatusView view_of(const drivers::ShakerSample& s);

// The armed run's periods, until the campaign ends (L.result.end set) or the daemon stops.
void run_ticks(Loop& L, Strategy& strategy);

}  // namespace hystlab::daemon
