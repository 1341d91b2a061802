#include "can_endpoint.hpp"

#include <linux/sockios.h>
#include <sys/ioctl.h>

#include <sys/socket.h>

#include <cerrno>
#include <cstdio>
#include <limits>

#include "hystlab/protocols/can_protocol.hpp"

namespace hystlab::sim {
namespace can = protocols::can;
using protocols::Signal;

void CanEndpoint::receive(SimRig& rig) {
  for (;;) {
    can_frame f{};
    const ssize_t n = recv(fd_, &f, sizeof f, MSG_DONTWAIT);
    if (n == 0) gone_ = true;
    if (n != static_cast<ssize_t>(sizeof f)) return;
    can::Message m;
    if (can::decode(f, node_, m)) continue;  // not ours, or malformed: a rig ignores it
    SignalValues v;
    v.fill(std::numeric_limits<double>::quiet_NaN());
    auto set = [&](Signal s, double x) { v[static_cast<std::size_t>(s)] = x; };
    if (const auto* c = std::get_if<can::Command>(&m)) {
      set(Signal::setpoint_mm, c->setpoint_mm);
      set(Signal::ramp_rate_mm_s, c->ramp_rate_mm_s);
      set(Signal::enable, c->enable);
      set(Signal::hold, c->hold);
      set(Signal::estop, c->estop);
      set(Signal::fault_reset, c->fault_reset);
      set(Signal::mode, c->mode);
    } else if (const auto* s = std::get_if<can::ShakerCommand>(&m)) {
      set(Signal::drive_frequency_hz, s->frequency_hz);
      set(Signal::drive_amplitude_mm, s->amplitude_mm);
      set(Signal::shaker_enable, s->enable);
    } else {
      continue;
    }
    rig.apply(v);
  }
}

bool CanEndpoint::host_caught_up() const noexcept {
  int queued = 0;
  return ioctl(fd_, SIOCOUTQ, &queued) != 0 || queued == 0;
}

void CanEndpoint::maybe_send(double now_s, const SignalValues& m, protocols::RigKind kind, const Faults& faults) {
  if (now_s < next_s_) return;
  next_s_ = next_s_ == 0 ? now_s + period_s_ : next_s_ + period_s_;
  if (next_s_ < now_s) next_s_ = now_s + period_s_;  // fell behind: skip, do not burst
  if (faults.can_silent || gone_) return;
  auto g = [&](Signal s) { return m[static_cast<std::size_t>(s)]; };
  can::Message first;
  if (kind == protocols::RigKind::load_frame)
    first = can::StatusA{g(Signal::displacement_mm), g(Signal::force_N)};
  else
    first = can::ShakerStatus{g(Signal::base_accel_m_s2), g(Signal::mass_accel_m_s2), g(Signal::base_displacement_mm), g(Signal::mass_displacement_mm)};
  const double cmd = kind == protocols::RigKind::load_frame ? g(Signal::command_mm) : 0.0;
  const can::Message cycle[] = {first, can::StatusB{cmd, static_cast<std::uint16_t>(g(Signal::status_word)), static_cast<std::uint16_t>(g(Signal::fault_code))},
                                can::Heartbeat{heartbeat_++}, can::StatusC{static_cast<std::uint32_t>(g(Signal::sample_counter))}};
  for (const auto& msg : cycle) {
    can_frame f{};
    if (can::encode(msg, node_, f)) continue;  // a value the frame cannot carry is not sent
    if (send(fd_, &f, sizeof f, MSG_DONTWAIT | MSG_NOSIGNAL) < 0 && errno != EAGAIN) gone_ = errno == EPIPE || errno == ECONNRESET;
  }
}

}  // namespace hystlab::sim
