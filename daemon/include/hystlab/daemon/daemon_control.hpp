#pragma once
// The daemon behind the interface front ends use (hystlab/control/daemon_interface.hpp): the
// only place that turns the daemon's own types (rig workers' live feeds, driver health, plans,
// the writer's statistics) into the interface's values.
#include <memory>

#include "hystlab/control/daemon_interface.hpp"
#include "hystlab/daemon/daemon.hpp"

namespace hystlab::daemon {

// The interface to d; d must outlive it.
[[nodiscard]] std::unique_ptr<control::DaemonInterface> make_control(Daemon& d);

}  // namespace hystlab::daemon
