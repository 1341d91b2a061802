#include "hystlab/drivers/modbus_rig.hpp"

#include <modbus/modbus.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <map>
#include <stdexcept>

namespace hystlab::drivers {
namespace {
using protocols::ModbusTable;
using protocols::Signal;

RigError classify(int err) {
  if (err == ETIMEDOUT) return RigError::timeout;
  if (err >= EMBXILFUN && err <= EMBXGTAR) return RigError::exception_response;
  if (err == EMBBADCRC) return RigError::crc_error;
  if (err == EMBBADDATA || err == EMBBADEXC || err == EMBUNKEXC || err == EMBMDATA || err == EMBBADSLAVE) return RigError::protocol_error;
  return RigError::connection_lost;  // ECONNRESET, EPIPE, ECONNREFUSED, EBADF, EIO, ...
}

void set_timeout(modbus_t* ctx, double s, bool byte) {
  const auto sec = static_cast<uint32_t>(s);
  const auto usec = static_cast<uint32_t>(std::lround((s - sec) * 1e6));
  if (byte)
    modbus_set_byte_timeout(ctx, sec, usec);
  else
    modbus_set_response_timeout(ctx, sec, usec);
}

double micros_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

ModbusRig::ModbusRig(ModbusRigConfig config) : cfg_(std::move(config)) {
  for (const auto& b : cfg_.map.measurement_blocks()) block_words_.emplace_back(b.count, 0);
  if (cfg_.slave == 0) cfg_.slave = cfg_.map.slave_id();
  if (cfg_.block_reads) {
    const auto& w = cfg_.map.sample_window();
    if (!w) throw std::invalid_argument(cfg_.name + ": block reads need a register map with a sample_window");
    const bool frame = cfg_.map.kind() == protocols::RigKind::load_frame;
    const std::initializer_list<Signal> needed = {Signal::displacement_mm, Signal::force_N, Signal::status_word};
    const std::initializer_list<Signal> shaker_needed = {Signal::base_displacement_mm, Signal::mass_displacement_mm, Signal::status_word};
    for (const Signal s : frame ? needed : shaker_needed)
      if (std::find(w->fields.begin(), w->fields.end(), s) == w->fields.end())
        throw std::invalid_argument(cfg_.name + ": block reads need " + std::string(protocols::signal_name(s)) + " in the map's sample_window.fields");
    window_words_.assign(static_cast<std::size_t>(w->records * w->record_width), 0);
    window_records_.assign(static_cast<std::size_t>(w->records), protocols::SignalArray{});
  }
}

ModbusRig::~ModbusRig() { disconnect(); }

std::string ModbusRig::describe() const {
  return cfg_.name + (cfg_.transport == ModbusRigConfig::Transport::tcp ? " (modbus tcp " + cfg_.host + ":" + std::to_string(cfg_.port) + ")"
                                                                        : " (modbus rtu " + cfg_.device + ")");
}

void ModbusRig::disconnect() noexcept {
  if (ctx_) {
    modbus_close(ctx_);
    modbus_free(ctx_);
    ctx_ = nullptr;
  }
  connected_ = false;
}

std::error_code ModbusRig::connect(double now_s) noexcept {
  disconnect();
  last_now_ = now_s;
  have_window_counter_ = false;  // block reads start afresh: what came before is not "lost"
  have_poll_anchor_ = false;
  enable_known_ = false;
  ctx_ = cfg_.transport == ModbusRigConfig::Transport::tcp ? modbus_new_tcp(cfg_.host.c_str(), cfg_.port)
                                                           : modbus_new_rtu(cfg_.device.c_str(), cfg_.baud, cfg_.parity, cfg_.data_bits, cfg_.stop_bits);
  if (!ctx_) return fail(errno, "create context");
  modbus_set_slave(ctx_, cfg_.slave);
  set_timeout(ctx_, cfg_.response_timeout_s, false);
  set_timeout(ctx_, cfg_.byte_timeout_s, true);
  if (modbus_connect(ctx_) == -1) {
    const int err = errno;
    modbus_free(ctx_);
    ctx_ = nullptr;
    back_off();
    return fail(err == ETIMEDOUT ? ECONNREFUSED : err, "connect");
  }
  connected_ = true;
  backoff_ = 0;
  return {};
}

std::error_code ModbusRig::ensure_connected(double now_s) noexcept {
  last_now_ = now_s;
  if (connected_) return {};
  if (now_s < next_attempt_) return RigError::not_connected;
  health_.record_reconnect();
  return connect(now_s);
}

std::error_code ModbusRig::fail(int err, const char* op) noexcept {
  const RigError kind = classify(err);
  enable_known_ = false;
  health_.record_error(kind);
  if (kind == RigError::connection_lost && ctx_) {
    modbus_close(ctx_);
    back_off();
  } else if (ctx_ && (kind == RigError::timeout || kind == RigError::crc_error || kind == RigError::protocol_error)) {
    resync();
  }
  ++episode_count_;
  if (episode_ != static_cast<int>(kind)) {  // once per episode, not once per poll
    spdlog::warn("{}: {} failed: {} ({}); further errors are counted until it recovers", describe(), op, make_error_code(kind).message(), modbus_strerror(err));
    episode_ = static_cast<int>(kind);
  }
  return kind;
}

// libmodbus's flush drops only what has already arrived: an answer to a timed-out request that
// arrives later is taken for the next request's, and the one after it, for ever (a TCP mismatch
// of transaction ids; on RTU it would pass as valid). TCP: a fresh connection cannot carry it.
// RTU: wait until the line is quiet, then drop what came.
void ModbusRig::resync() noexcept {
  if (cfg_.transport == ModbusRigConfig::Transport::rtu) {
    drain_line();
    return;
  }
  modbus_close(ctx_);
  health_.record_reconnect();
  if (modbus_connect(ctx_) == -1) {
    health_.record_error(RigError::connection_lost);
    back_off();
  }
}

// Not connected: the next attempt waits a back-off that doubles up to reconnect_max_s.
void ModbusRig::back_off() noexcept {
  connected_ = false;
  backoff_ = backoff_ > 0 ? std::min(backoff_ * 2, cfg_.reconnect_max_s) : cfg_.reconnect_min_s;
  next_attempt_ = last_now_ + backoff_;
}

void ModbusRig::drain_line() noexcept {
  const int fd = modbus_get_socket(ctx_);
  if (fd < 0) return;
  auto wait_ms = static_cast<int>(std::ceil(cfg_.response_timeout_s * 1e3));  // a late answer starts within this
  std::uint8_t junk[256];
  for (int guard = 0; guard < 64; ++guard) {  // bounded: a chattering line cannot hold us here
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, wait_ms) <= 0 || read(fd, junk, sizeof junk) <= 0) break;
    wait_ms = static_cast<int>(std::ceil(cfg_.byte_timeout_s * 1e3));  // ... and ends with a quiet gap
  }
  modbus_flush(ctx_);
}

void ModbusRig::succeed() noexcept {
  if (episode_ != 0) {
    spdlog::info("{}: recovered after {} failed transactions", describe(), episode_count_);
    episode_ = 0;
    episode_count_ = 0;
  }
}

std::error_code ModbusRig::read_blocks(double now_s) noexcept {
  if (auto ec = ensure_connected(now_s)) return ec;
  const auto& blocks = cfg_.map.measurement_blocks();
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const auto& blk = blocks[b];
    auto& w = block_words_[b];
    const auto t0 = std::chrono::steady_clock::now();
    int rc = -1;
    if (blk.table == ModbusTable::input_register)
      rc = modbus_read_input_registers(ctx_, blk.start, blk.count, w.data());
    else if (blk.table == ModbusTable::holding_register)
      rc = modbus_read_registers(ctx_, blk.start, blk.count, w.data());
    else {
      std::uint8_t bits[2000];
      rc = blk.table == ModbusTable::coil ? modbus_read_bits(ctx_, blk.start, blk.count, bits) : modbus_read_input_bits(ctx_, blk.start, blk.count, bits);
      for (int k = 0; k < blk.count && rc > 0; ++k) w[static_cast<std::size_t>(k)] = bits[k];
    }
    if (rc == -1) return fail(errno, "read");
    if (rc != blk.count) return fail(EMBBADDATA, "read");
    health_.record_transaction(false, micros_since(t0));
  }
  succeed();
  return {};
}

std::error_code ModbusRig::value_of(Signal s, double& v) const noexcept {
  const protocols::MapEntry* e = cfg_.map.find(s);
  if (!e) return RigError::unsupported;
  const auto& blocks = cfg_.map.measurement_blocks();
  for (std::size_t b = 0; b < blocks.size(); ++b)
    if (blocks[b].table == e->table && e->address >= blocks[b].start && e->address + e->width() <= blocks[b].start + blocks[b].count) {
      const auto& w = block_words_[b];
      const auto ec = protocols::decode(*e, std::span(w).subspan(e->address - blocks[b].start), v);
      if (ec == protocols::ProtocolError::out_of_range || ec == protocols::ProtocolError::not_finite) return RigError::out_of_range;
      return ec ? make_error_code(RigError::protocol_error) : std::error_code{};
    }
  return RigError::unsupported;
}

std::error_code ModbusRig::check_stale(double now_s, std::uint32_t counter) noexcept {
  if (counter != last_counter_ || counter_changed_at_ < 0) {
    last_counter_ = counter;
    counter_changed_at_ = now_s;
    return {};
  }
  if (now_s - counter_changed_at_ > cfg_.stale_after_s) {
    health_.record_error(RigError::stale_data);
    return RigError::stale_data;
  }
  return {};
}

std::error_code ModbusRig::read_sample(double now_s, RigSample& out) noexcept {
  if (cfg_.map.kind() != protocols::RigKind::load_frame) return RigError::unsupported;
  if (auto ec = read_blocks(now_s)) return ec;
  double d = 0, f = 0, c = 0, st = 0, fc = 0, hb = 0, n = 0;
  for (auto [sig, dst] : {std::pair{Signal::displacement_mm, &d},
                          {Signal::force_N, &f},
                          {Signal::status_word, &st},
                          {Signal::fault_code, &fc},
                          {Signal::heartbeat, &hb},
                          {Signal::sample_counter, &n}})
    if (auto ec = value_of(sig, *dst)) {
      health_.record_error(static_cast<RigError>(ec.value()));
      return ec;
    }
  if (cfg_.map.find(Signal::command_mm)) (void)value_of(Signal::command_mm, c);
  out =
      RigSample{now_s, c, d, f, static_cast<std::uint16_t>(st), static_cast<std::uint16_t>(fc), static_cast<std::uint32_t>(hb), static_cast<std::uint32_t>(n)};
  return check_stale(now_s, out.sample_counter);
}

// --- Block reads of the controller's sample window (newest record first) ---

std::error_code ModbusRig::read_window_page(int first, int count) noexcept {
  const protocols::SampleWindow& w = *cfg_.map.sample_window();
  const int words = count * w.record_width;
  const auto address = static_cast<int>(w.address) + first * w.record_width;
  std::uint16_t* dst = window_words_.data() + first * w.record_width;
  const auto t0 = std::chrono::steady_clock::now();
  const int rc =
      w.table == ModbusTable::input_register ? modbus_read_input_registers(ctx_, address, words, dst) : modbus_read_registers(ctx_, address, words, dst);
  if (rc == -1) return fail(errno, "read");
  if (rc != words) return fail(EMBBADDATA, "read");
  health_.record_transaction(false, micros_since(t0));
  return {};
}

// Reads pages of the window until it reaches a record already taken (usually the first page
// does); decodes the fresh ones into window_records_, newest first.
std::error_code ModbusRig::take_window(double now_s, int& fresh, bool& reached) noexcept {
  const protocols::SampleWindow& w = *cfg_.map.sample_window();
  const auto counter_at = static_cast<std::size_t>(Signal::sample_counter);
  fresh = 0;
  reached = false;
  for (int first = 0; first < w.records && !reached; first += w.records_per_read()) {
    const int count = std::min(w.records_per_read(), w.records - first);
    if (auto ec = read_window_page(first, count)) return ec;
    for (int k = first; k < first + count; ++k) {
      // The window may shift between pages (the controller samples on): a record seen on the
      // previous page shows again, and is skipped. Fresh records are packed at the front.
      protocols::SignalArray& r = window_records_[static_cast<std::size_t>(k)];
      const auto words = std::span<const std::uint16_t>(window_words_).subspan(static_cast<std::size_t>(k * w.record_width));
      if (const auto ec = protocols::decode_record(cfg_.map, w, words, r)) {
        const RigError kind =
            ec == protocols::ProtocolError::out_of_range || ec == protocols::ProtocolError::not_finite ? RigError::out_of_range : RigError::protocol_error;
        health_.record_error(kind);
        return kind;
      }
      const auto c = static_cast<std::uint32_t>(r[counter_at]);
      if (k == 0 && (!have_window_counter_ || static_cast<std::int32_t>(c - window_counter_) < 0)) {
        // The first block, or the controller restarted its counter: its clock starts here.
        if (have_window_counter_) spdlog::warn("{}: the controller's sample counter went back; its clock is re-anchored", describe());
        have_window_counter_ = true;
        window_counter_ = c - 1;
        anchor_time_s_ = now_s;
        anchor_counter64_ = window_counter64_ = static_cast<std::int64_t>(c) - 1;
        fresh = 1;
        reached = true;
        break;
      }
      if (static_cast<std::int32_t>(c - window_counter_) <= 0) {
        reached = true;
        break;
      }
      if (fresh > 0 && static_cast<std::int32_t>(c - static_cast<std::uint32_t>(window_records_[static_cast<std::size_t>(fresh - 1)][counter_at])) >= 0)
        continue;
      if (fresh != k) window_records_[static_cast<std::size_t>(fresh)] = r;
      ++fresh;
    }
  }
  succeed();
  return {};
}

// The controller's time of the next fresh record (oldest first): its counter extended to 64
// bits from the anchor.
double ModbusRig::record_time(std::uint32_t c) noexcept {
  window_counter64_ += static_cast<std::int32_t>(c - window_counter_);
  window_counter_ = c;
  return anchor_time_s_ + static_cast<double>(window_counter64_ - anchor_counter64_) * cfg_.map.sample_window()->period_s;
}

namespace {
double at(const protocols::SignalArray& r, Signal s) { return r[static_cast<std::size_t>(s)]; }
// How many of the fresh records the caller's buffer takes (it never grows on this thread).
template <class Sample>
int room_for(int fresh, const std::vector<Sample>& out, IoHealth& health) noexcept {
  const int room = static_cast<int>(std::min<std::size_t>(out.capacity(), static_cast<std::size_t>(fresh)));
  if (room < fresh) health.record_lost(static_cast<std::uint64_t>(fresh - room));
  return room;
}
}  // namespace

// Fresh records to samples, oldest first, timed by the controller's counter.
void ModbusRig::emit_window(int fresh, std::vector<RigSample>& out) noexcept {
  const bool has_command = cfg_.map.find(Signal::command_mm) != nullptr;
  for (int k = room_for(fresh, out, health_) - 1; k >= 0; --k) {
    const protocols::SignalArray& r = window_records_[static_cast<std::size_t>(k)];
    const auto c = static_cast<std::uint32_t>(at(r, Signal::sample_counter));
    const double command = has_command && !std::isnan(at(r, Signal::command_mm)) ? at(r, Signal::command_mm) : 0.0;
    out.push_back(RigSample{record_time(c), command, at(r, Signal::displacement_mm), at(r, Signal::force_N),
                            static_cast<std::uint16_t>(at(r, Signal::status_word)), static_cast<std::uint16_t>(at(r, Signal::fault_code)), c, c});
  }
}

// A shaker's record: a field the window does not carry (the accelerations, say) reads 0, as
// the records start (window_records_ is zeroed once, and decode_record leaves other fields).
void ModbusRig::emit_window(int fresh, std::vector<ShakerSample>& out) noexcept {
  for (int k = room_for(fresh, out, health_) - 1; k >= 0; --k) {
    const protocols::SignalArray& r = window_records_[static_cast<std::size_t>(k)];
    const auto c = static_cast<std::uint32_t>(at(r, Signal::sample_counter));
    out.push_back(ShakerSample{record_time(c), at(r, Signal::base_accel_m_s2), at(r, Signal::mass_accel_m_s2), at(r, Signal::base_displacement_mm),
                               at(r, Signal::mass_displacement_mm), static_cast<std::uint16_t>(at(r, Signal::status_word)),
                               static_cast<std::uint16_t>(at(r, Signal::fault_code)), c, c});
  }
}

// The window's fresh records; when the whole window is newer than what was taken, the rest is
// gone: counted, and the time axis keeps the gap.
std::error_code ModbusRig::take_fresh(double now_s, int& fresh) noexcept {
  fresh = 0;
  if (auto ec = ensure_connected(now_s)) return ec;
  bool reached = false;
  const std::uint32_t before = window_counter_;
  if (auto ec = take_window(now_s, fresh, reached)) return ec;
  if (!reached && fresh > 0) {
    const auto newest = static_cast<std::uint32_t>(window_records_[0][static_cast<std::size_t>(Signal::sample_counter)]);
    health_.record_lost(static_cast<std::uint64_t>(static_cast<std::uint32_t>(newest - before)) - static_cast<std::uint64_t>(fresh));
    window_counter_ = newest - static_cast<std::uint32_t>(fresh);
    window_counter64_ += static_cast<std::int32_t>(window_counter_ - before);
  }
  return {};
}

std::error_code ModbusRig::read_samples(double now_s, std::vector<RigSample>& out) noexcept {
  if (!cfg_.block_reads) return Rig::read_samples(now_s, out);
  if (cfg_.map.kind() != protocols::RigKind::load_frame) return out.clear(), RigError::unsupported;
  out.clear();
  int fresh = 0;
  if (auto ec = take_fresh(now_s, fresh)) return ec;
  emit_window(fresh, out);
  return check_stale(now_s, window_counter_);
}

std::error_code ModbusRig::read_shaker_samples(double now_s, std::vector<ShakerSample>& out) noexcept {
  if (!cfg_.block_reads) return Rig::read_shaker_samples(now_s, out);
  out.clear();
  if (cfg_.map.kind() != protocols::RigKind::shaker) return RigError::unsupported;
  int fresh = 0;
  if (auto ec = take_fresh(now_s, fresh)) return ec;
  emit_window(fresh, out);
  return check_stale(now_s, window_counter_);
}

std::error_code ModbusRig::read_shaker(double now_s, ShakerSample& out) noexcept {
  if (cfg_.map.kind() != protocols::RigKind::shaker) return RigError::unsupported;
  if (auto ec = read_blocks(now_s)) return ec;
  double v[8] = {};
  const Signal sigs[8] = {Signal::base_accel_m_s2, Signal::mass_accel_m_s2, Signal::base_displacement_mm, Signal::mass_displacement_mm, Signal::status_word,
                          Signal::fault_code,      Signal::heartbeat,       Signal::sample_counter};
  for (int k = 0; k < 8; ++k)
    if (auto ec = value_of(sigs[k], v[k])) return ec;
  const auto counter = static_cast<std::uint32_t>(v[7]);
  out = ShakerSample{clock_time(now_s, counter),       v[0],   v[1], v[2], v[3], static_cast<std::uint16_t>(v[4]), static_cast<std::uint16_t>(v[5]),
                     static_cast<std::uint32_t>(v[6]), counter};
  return check_stale(now_s, counter);
}

// A sine fit needs the signal's own time axis: asked when the host happened to run, a shaker
// on a VM frozen for 0.4 s at a time (both vCPUs at once, twice a second) looked 0.4 s older
// than it was. Anchored at the first read (and again if the counter goes back).
double ModbusRig::clock_time(double now_s, std::uint32_t counter) noexcept {
  const double period = cfg_.map.sample_period_s();
  if (period <= 0) return now_s;
  // A 16-bit counter (one register) wraps every 65,536 samples: steps are taken at its width.
  const protocols::MapEntry* e = cfg_.map.find(Signal::sample_counter);
  const std::int64_t step = e && e->width() == 1 ? static_cast<std::int16_t>(static_cast<std::uint16_t>(counter - poll_counter_))
                                                 : static_cast<std::int64_t>(static_cast<std::int32_t>(counter - poll_counter_));
  if (!have_poll_anchor_ || step < 0) {
    have_poll_anchor_ = true;
    poll_anchor_s_ = now_s;
    poll_anchor64_ = poll_counter64_ = counter;
  } else {
    poll_counter64_ += step;
  }
  poll_counter_ = counter;
  return poll_anchor_s_ + static_cast<double>(poll_counter64_ - poll_anchor64_) * period;
}

std::error_code ModbusRig::write_signals(std::initializer_list<Write> writes) noexcept {
  if (auto ec = ensure_connected(last_now_)) return ec;
  std::map<int, std::uint16_t> regs;  // holding registers, written in contiguous runs
  std::vector<std::pair<int, bool>> coils;
  for (const Write& w : writes) {
    const protocols::MapEntry* e = cfg_.map.find(w.signal);
    if (!e) return RigError::unsupported;
    if ((e->min && w.value < *e->min) || (e->max && w.value > *e->max)) return RigError::out_of_range;
    std::uint16_t words[2];
    if (protocols::encode(*e, w.value, words)) return RigError::out_of_range;
    if (e->table == ModbusTable::coil)
      coils.emplace_back(e->address, words[0] != 0);
    else
      for (int k = 0; k < e->width(); ++k) regs[e->address + k] = words[k];
  }
  for (auto it = regs.begin(); it != regs.end();) {
    std::vector<std::uint16_t> run{it->second};
    const int start = it->first;
    for (++it; it != regs.end() && it->first == start + static_cast<int>(run.size()); ++it) run.push_back(it->second);
    const auto t0 = std::chrono::steady_clock::now();
    if (modbus_write_registers(ctx_, start, static_cast<int>(run.size()), run.data()) == -1) return fail(errno, "write");
    health_.record_transaction(true, micros_since(t0));
  }
  for (const auto& [addr, on] : coils) {
    const auto t0 = std::chrono::steady_clock::now();
    if (modbus_write_bit(ctx_, addr, on ? 1 : 0) == -1) return fail(errno, "write");
    health_.record_transaction(true, micros_since(t0));
  }
  succeed();
  return {};
}

std::error_code ModbusRig::arm(bool enable) noexcept { return write_signals({{Signal::enable, enable ? 1.0 : 0.0}}); }
std::error_code ModbusRig::hold(bool on) noexcept { return write_signals({{Signal::hold, on ? 1.0 : 0.0}}); }
std::error_code ModbusRig::estop(bool on) noexcept {
  enable_known_ = false;
  return write_signals({{Signal::estop, on ? 1.0 : 0.0}});
}
std::error_code ModbusRig::command(double setpoint_mm, double rate) noexcept {
  return write_signals({{Signal::setpoint_mm, setpoint_mm}, {Signal::ramp_rate_mm_s, rate}});
}
std::error_code ModbusRig::set_mode(std::uint16_t mode) noexcept {
  if (!cfg_.map.find(Signal::mode)) return RigError::unsupported;
  return write_signals({{Signal::mode, static_cast<double>(mode)}});
}
// Release the e-stop first: a controller ignores the reset while its e-stop signal is on.
std::error_code ModbusRig::reset_faults() noexcept {
  if (auto ec = estop(false)) return ec;
  if (!cfg_.map.find(Signal::fault_reset)) return {};
  if (auto ec = write_signals({{Signal::fault_reset, 1.0}})) return ec;
  return write_signals({{Signal::fault_reset, 0.0}});  // the pulse ends: the next reset is a new edge
}
std::error_code ModbusRig::write_host_heartbeat(std::uint32_t value) noexcept {
  const protocols::MapEntry* e = cfg_.map.find(Signal::host_heartbeat);
  if (!e) return RigError::unsupported;
  // A counter wraps: a 16-bit register carries the low 16 bits.
  return write_signals({{Signal::host_heartbeat, static_cast<double>(e->width() == 1 ? value & 0xFFFFU : value)}});
}
// The drive alone while enable is as last written (a controller that took the enable coil
// once needs no rewrite of it 1,000 times a sweep); anything that may have changed it on the
// controller side (a reconnect, a failed transaction, an e-stop, a reset) writes it again.
std::error_code ModbusRig::command_shaker(double f, double a, bool enable) noexcept {
  // A disable is always written (the supervisor's retry of one the controller did not take
  // must reach the coil); only a standing enable is left as it is.
  if (enable && enable_known_ && enable_written_) return write_signals({{Signal::drive_frequency_hz, f}, {Signal::drive_amplitude_mm, a}});
  if (auto ec = write_signals({{Signal::drive_frequency_hz, f}, {Signal::drive_amplitude_mm, a}, {Signal::shaker_enable, enable ? 1.0 : 0.0}})) return ec;
  enable_known_ = true, enable_written_ = enable;
  return {};
}

}  // namespace hystlab::drivers
