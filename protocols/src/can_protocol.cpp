#include "hystlab/protocols/can_protocol.hpp"

#include <cmath>
#include <cstring>
#include <type_traits>

namespace hystlab::protocols::can {
namespace {

template <class T>
void put(can_frame& f, int at, T v) {
  using U = std::make_unsigned_t<T>;
  const U u = static_cast<U>(v);
  for (std::size_t b = 0; b < sizeof(T); ++b) f.data[static_cast<std::size_t>(at) + b] = static_cast<std::uint8_t>(u >> (8 * b));
}

template <class T>
T get(const can_frame& f, int at) {
  using U = std::make_unsigned_t<T>;
  U u = 0;
  for (std::size_t b = 0; b < sizeof(T); ++b) u = static_cast<U>(u | (static_cast<U>(f.data[static_cast<std::size_t>(at) + b]) << (8 * b)));
  return static_cast<T>(u);
}

// value / unit as an integer of type T, or out_of_range.
template <class T>
bool scaled(double value, double unit, T& out) {
  if (!std::isfinite(value)) return false;
  const double r = std::round(value / unit);
  if (r < static_cast<double>(std::numeric_limits<T>::min()) || r > static_cast<double>(std::numeric_limits<T>::max())) return false;
  out = static_cast<T>(r);
  return true;
}

void start(can_frame& f, std::uint32_t base, int node, int dlc) {
  std::memset(&f, 0, sizeof f);
  f.can_id = base + static_cast<std::uint32_t>(node);
  f.can_dlc = static_cast<std::uint8_t>(dlc);
}

}  // namespace

std::error_code encode(const Message& m, int node, can_frame& f) noexcept {
  if (node < 1 || node > 127) return ProtocolError::out_of_range;
  bool ok = true;
  if (const auto* c = std::get_if<Command>(&m)) {
    std::int32_t sp = 0;
    std::uint16_t rate = 0;
    ok = scaled(c->setpoint_mm, 1e-3, sp) && scaled(c->ramp_rate_mm_s, 1e-2, rate) && c->mode <= kMaxMode;
    start(f, kCommand, node, 8);
    put(f, 0, sp);
    put(f, 4, rate);
    f.data[6] = static_cast<std::uint8_t>((c->enable ? 1 : 0) | (c->hold ? 2 : 0) | (c->estop ? 4 : 0) | (c->fault_reset ? 8 : 0));
    f.data[7] = c->mode;
  } else if (const auto* a = std::get_if<StatusA>(&m)) {
    std::int32_t d = 0, fo = 0;
    ok = scaled(a->displacement_mm, 1e-3, d) && scaled(a->force_N, 1e-3, fo);
    start(f, kStatusA, node, 8);
    put(f, 0, d);
    put(f, 4, fo);
  } else if (const auto* b = std::get_if<StatusB>(&m)) {
    std::int32_t c2 = 0;
    ok = scaled(b->command_mm, 1e-3, c2);
    start(f, kStatusB, node, 8);
    put(f, 0, c2);
    put(f, 4, b->status_word);
    put(f, 6, b->fault_code);
  } else if (const auto* c3 = std::get_if<StatusC>(&m)) {
    start(f, kStatusC, node, 4);
    put(f, 0, c3->sample_counter);
  } else if (const auto* h = std::get_if<Heartbeat>(&m)) {
    start(f, kHeartbeat, node, 1);
    f.data[0] = h->counter;
  } else if (const auto* sc = std::get_if<ShakerCommand>(&m)) {
    std::uint16_t fr = 0, am = 0;
    ok = scaled(sc->frequency_hz, 1e-2, fr) && scaled(sc->amplitude_mm, 1e-3, am);
    start(f, kShakerCommand, node, 5);
    put(f, 0, fr);
    put(f, 2, am);
    f.data[4] = sc->enable ? 1 : 0;
  } else if (const auto* ss = std::get_if<ShakerStatus>(&m)) {
    std::int16_t ba = 0, ma = 0, bd = 0, md = 0;
    ok = scaled(ss->base_accel_m_s2, 1e-2, ba) && scaled(ss->mass_accel_m_s2, 1e-2, ma) && scaled(ss->base_displacement_mm, 1e-3, bd) &&
         scaled(ss->mass_displacement_mm, 1e-3, md);
    start(f, kShakerStatus, node, 8);
    put(f, 0, ba);
    put(f, 2, ma);
    put(f, 4, bd);
    put(f, 6, md);
  }
  return ok ? std::error_code{} : make_error_code(ProtocolError::out_of_range);
}

std::error_code decode(const can_frame& f, int node, Message& out) noexcept {
  // Anything beyond an 11-bit identifier (extended, RTR and error flags, stray high bits) is not ours.
  if (f.can_id & ~static_cast<canid_t>(CAN_SFF_MASK)) return ProtocolError::unknown_id;
  const std::uint32_t id = f.can_id & CAN_SFF_MASK;
  if (node < 1 || node > 127 || (id & 0x7FU) != static_cast<std::uint32_t>(node)) return ProtocolError::unknown_id;
  auto need = [&](int dlc) { return f.can_dlc == dlc; };
  switch (id - static_cast<std::uint32_t>(node)) {
    case kCommand: {
      if (!need(8)) return ProtocolError::wrong_length;
      if (f.data[6] & ~0x0FU) return ProtocolError::reserved_bits;
      if (f.data[7] > kMaxMode) return ProtocolError::out_of_range;
      out = Command{get<std::int32_t>(f, 0) * 1e-3,
                    get<std::uint16_t>(f, 4) * 1e-2,
                    (f.data[6] & 1) != 0,
                    (f.data[6] & 2) != 0,
                    (f.data[6] & 4) != 0,
                    f.data[7],
                    (f.data[6] & 8) != 0};
      return {};
    }
    case kStatusA:
      if (!need(8)) return ProtocolError::wrong_length;
      out = StatusA{get<std::int32_t>(f, 0) * 1e-3, get<std::int32_t>(f, 4) * 1e-3};
      return {};
    case kStatusB:
      if (!need(8)) return ProtocolError::wrong_length;
      out = StatusB{get<std::int32_t>(f, 0) * 1e-3, get<std::uint16_t>(f, 4), get<std::uint16_t>(f, 6)};
      return {};
    case kStatusC:
      if (!need(4)) return ProtocolError::wrong_length;
      out = StatusC{get<std::uint32_t>(f, 0)};
      return {};
    case kHeartbeat:
      if (!need(1)) return ProtocolError::wrong_length;
      out = Heartbeat{f.data[0]};
      return {};
    case kShakerCommand:
      if (!need(5)) return ProtocolError::wrong_length;
      if (f.data[4] & ~0x01U) return ProtocolError::reserved_bits;
      out = ShakerCommand{get<std::uint16_t>(f, 0) * 1e-2, get<std::uint16_t>(f, 2) * 1e-3, f.data[4] != 0};
      return {};
    case kShakerStatus:
      if (!need(8)) return ProtocolError::wrong_length;
      out = ShakerStatus{get<std::int16_t>(f, 0) * 1e-2, get<std::int16_t>(f, 2) * 1e-2, get<std::int16_t>(f, 4) * 1e-3, get<std::int16_t>(f, 6) * 1e-3};
      return {};
    default:
      return ProtocolError::unknown_id;
  }
}

}  // namespace hystlab::protocols::can
