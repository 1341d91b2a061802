#include "modbus_endpoint.hpp"

#include <arpa/inet.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <pty.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>

#include "hystlab/protocols/modbus_crc.hpp"
#include "hystlab/protocols/sample_record.hpp"

namespace hystlab::sim {
using protocols::ModbusTable;

namespace {
int table_size(const protocols::RegisterMap& m, ModbusTable t) {
  int n = 0;
  for (const auto& e : m.entries())
    if (e.table == t) n = std::max(n, e.address + e.width());
  if (const auto& w = m.sample_window(); w && w->table == t) n = std::max(n, w->address + w->records * w->record_width);
  return n;
}
}  // namespace

ModbusEndpoint::ModbusEndpoint(Transport t, const std::string& address, int port, protocols::RegisterMap map)
    : transport_(t), map_(std::move(map)), address_(address), port_(port) {
  mapping_ = modbus_mapping_new(table_size(map_, ModbusTable::coil), table_size(map_, ModbusTable::discrete_input),
                                table_size(map_, ModbusTable::holding_register), table_size(map_, ModbusTable::input_register));
  if (!mapping_) throw std::runtime_error("hystlab-sim: cannot allocate the register map");
  if (t == Transport::tcp) {
    ctx_ = modbus_new_tcp(address.c_str(), port);
    if (!ctx_) throw std::runtime_error("hystlab-sim: bad TCP address " + address);
    listen_fd_ = modbus_tcp_listen(ctx_, 16);
    if (listen_fd_ < 0) throw std::runtime_error("hystlab-sim: cannot listen on " + address + ":" + std::to_string(port) + ": " + modbus_strerror(errno));
    sockaddr_in sa{};
    socklen_t len = sizeof sa;
    getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&sa), &len);
    port_ = ntohs(sa.sin_port);
  } else {
    if (openpty(&pty_master_, &pty_slave_, nullptr, nullptr, nullptr) != 0) throw std::runtime_error("hystlab-sim: cannot open a pseudo-terminal");
    termios tio{};
    tcgetattr(pty_slave_, &tio);
    cfmakeraw(&tio);  // no echo or line editing before the client sets its own modes
    tcsetattr(pty_slave_, TCSANOW, &tio);
    pty_path_ = ttyname(pty_slave_);
    ctx_ = modbus_new_rtu(pty_path_.c_str(), 115200, 'N', 8, 1);
    modbus_set_socket(ctx_, pty_master_);  // a master has no path: drive its fd directly
  }
  modbus_set_slave(ctx_, map_.slave_id());
  if (const auto& w = map_.sample_window()) window_ring_.assign(static_cast<std::size_t>(w->records * w->record_width), 0);
}

ModbusEndpoint::~ModbusEndpoint() {
  drop_clients();
  if (listen_fd_ >= 0) close(listen_fd_);
  if (pty_slave_ >= 0) close(pty_slave_);
  if (pty_master_ >= 0) close(pty_master_);
  if (ctx_) modbus_free(ctx_);
  if (mapping_) modbus_mapping_free(mapping_);
}

std::string ModbusEndpoint::where() const {
  return transport_ == Transport::tcp ? "modbus-tcp " + address_ + ":" + std::to_string(port_) : "modbus-rtu " + pty_path_;
}

void ModbusEndpoint::fds(std::vector<int>& out) const {
  if (transport_ == Transport::rtu) {
    out.push_back(pty_master_);
    return;
  }
  out.push_back(listen_fd_);
  out.insert(out.end(), clients_.begin(), clients_.end());
}

void ModbusEndpoint::drop_clients() {
  for (int fd : clients_) close(fd);
  clients_.clear();
}

void ModbusEndpoint::handle(int fd, const Faults& faults, SimRig& rig) {
  if (fd == listen_fd_) {
    const int c = accept(listen_fd_, nullptr, nullptr);
    if (c < 0) return;
    if (faults.drop) {
      close(c);
      return;
    }
    const int one = 1;
    setsockopt(c, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    clients_.push_back(c);
    return;
  }
  serve(fd, faults, rig);
}

void ModbusEndpoint::serve(int fd, const Faults& faults, SimRig& rig) {
  std::uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
  modbus_set_socket(ctx_, fd);
  const int rc = modbus_receive(ctx_, query);
  if (rc == -1) {
    if (transport_ == Transport::tcp) {
      close(fd);
      clients_.erase(std::remove(clients_.begin(), clients_.end(), fd), clients_.end());
    } else {
      modbus_flush(ctx_);
    }
    return;
  }
  if (rc == 0) return;  // not for us (RTU: another slave)
  if (faults.delay_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(faults.delay_ms));
  if (faults.late_step_ms > 0 && starts_new_step(query, rc)) std::this_thread::sleep_for(std::chrono::milliseconds(faults.late_step_ms));
  if (faults.exception > 0) {
    modbus_reply_exception(ctx_, query, static_cast<unsigned>(faults.exception));
    return;
  }
  if (faults.crc && transport_ == Transport::rtu) {
    reply_with_bad_crc(query, rc);
    return;
  }
  modbus_reply(ctx_, query, rc, mapping_);
  const int fn = query[modbus_get_header_length(ctx_)];
  if (fn == 0x05 || fn == 0x06 || fn == 0x0F || fn == 0x10) {
    rig.apply(written_commands());
    show_enable(rig);
  }
}

// The first write of each new drive frequency (a shaker's step: 0x06 or 0x10 over the entry's
// registers, to a frequency other than 0 and than the last one answered late), which the
// late-step fault answers late, as a controller busy retuning. Its retake is on time: once a step.
bool ModbusEndpoint::starts_new_step(const std::uint8_t* q, int length) {
  const protocols::MapEntry* e = map_.find(protocols::Signal::drive_frequency_hz);
  if (!e || e->table != ModbusTable::holding_register) return false;
  const int h = modbus_get_header_length(ctx_), fn = q[h];
  if ((fn != 0x06 && fn != 0x10) || h + 5 > length) return false;  // a write, whole enough to read its address
  const int first = (q[h + 1] << 8) | q[h + 2];
  const int count = fn == 0x06 ? 1 : ((q[h + 3] << 8) | q[h + 4]);
  const int at = fn == 0x06 ? h + 3 : h + 6;  // the first word's first byte
  std::array<std::uint16_t, 2> words{mapping_->tab_registers[e->address], mapping_->tab_registers[e->address + e->width() - 1]};
  bool touched = false;
  for (int k = 0; k < count && at + 2 * k + 1 < length; ++k) {
    const int i = first + k - e->address;
    if (i < 0 || i >= e->width()) continue;
    words[static_cast<std::size_t>(i)] = static_cast<std::uint16_t>((q[at + 2 * k] << 8) | q[at + 2 * k + 1]);
    touched = true;
  }
  double f = 0;
  if (!touched || protocols::decode(*e, std::span<const std::uint16_t>(words.data(), static_cast<std::size_t>(e->width())), f) || f == 0 || f == last_late_hz_)
    return false;
  last_late_hz_ = f;
  return true;
}

// A reset drops the drive's enable; the coil says so, and the host must write it again (an
// edge) before the drive moves, as on a real controller.
void ModbusEndpoint::show_enable(const SimRig& rig) {
  const protocols::MapEntry* e = map_.find(rig.enable_signal());
  if (e && e->table == ModbusTable::coil) mapping_->tab_bits[e->address] = rig.enable_command() ? 1 : 0;
}

// An RTU answer of the right shape whose CRC is wrong (fault injection).
void ModbusEndpoint::reply_with_bad_crc(const std::uint8_t* q, int length) {
  std::vector<std::uint8_t> a{q[0], q[1]};
  const int fn = q[1];
  const int addr = (q[2] << 8) | q[3], count = (q[4] << 8) | q[5];
  if (fn == 0x03 || fn == 0x04) {
    a.push_back(static_cast<std::uint8_t>(2 * count));
    const std::uint16_t* tab = fn == 0x03 ? mapping_->tab_registers : mapping_->tab_input_registers;
    for (int k = 0; k < count; ++k) {
      const std::uint16_t w = tab[addr + k];
      a.push_back(static_cast<std::uint8_t>(w >> 8));
      a.push_back(static_cast<std::uint8_t>(w & 0xFF));
    }
  } else {
    a.insert(a.end(), q + 2, q + std::min(6, length - 2));  // writes echo address and quantity
  }
  const std::uint16_t crc = protocols::crc16_modbus(a) ^ 0xFFFFU;
  a.push_back(static_cast<std::uint8_t>(crc & 0xFF));
  a.push_back(static_cast<std::uint8_t>(crc >> 8));
  (void)!write(pty_master_, a.data(), a.size());
}

SignalValues ModbusEndpoint::written_commands() const {
  SignalValues v;
  v.fill(std::numeric_limits<double>::quiet_NaN());
  for (const auto& e : map_.entries()) {
    if (!protocols::is_command(e.signal)) continue;
    std::uint16_t words[2] = {0, 0};
    if (e.table == ModbusTable::coil)
      words[0] = mapping_->tab_bits[e.address];
    else
      for (int k = 0; k < e.width(); ++k) words[k] = mapping_->tab_registers[e.address + k];
    double value = 0;
    if (!protocols::decode(e, std::span<const std::uint16_t>(words, 2), value)) v[static_cast<std::size_t>(e.signal)] = value;
  }
  return v;
}

void ModbusEndpoint::publish(const SignalValues& m) {
  if (const auto& w = map_.sample_window(); w && window_dirty_) {  // newest record first
    std::uint16_t* tab = w->table == ModbusTable::input_register ? mapping_->tab_input_registers : mapping_->tab_registers;
    const auto width = static_cast<std::size_t>(w->record_width), n = static_cast<std::size_t>(w->records);
    for (std::size_t k = 0; k < window_filled_; ++k) {
      const std::uint16_t* src = window_ring_.data() + ((window_head_ + n - k) % n) * width;
      std::copy(src, src + width, tab + w->address + k * width);
    }
    window_dirty_ = false;
  }
  for (const auto& e : map_.entries()) {
    const double value = m[static_cast<std::size_t>(e.signal)];
    if (protocols::is_command(e.signal) || std::isnan(value)) continue;
    std::uint16_t words[2] = {0, 0};
    if (protocols::encode(e, value, words)) continue;  // out of the type's range: keep the last value
    switch (e.table) {
      case ModbusTable::coil:
        mapping_->tab_bits[e.address] = static_cast<std::uint8_t>(words[0]);
        break;
      case ModbusTable::discrete_input:
        mapping_->tab_input_bits[e.address] = static_cast<std::uint8_t>(words[0]);
        break;
      case ModbusTable::holding_register:
        for (int k = 0; k < e.width(); ++k) mapping_->tab_registers[e.address + k] = words[k];
        break;
      case ModbusTable::input_register:
        for (int k = 0; k < e.width(); ++k) mapping_->tab_input_registers[e.address + k] = words[k];
        break;
    }
  }
}

void ModbusEndpoint::record(const SignalValues& m) {
  const auto& w = map_.sample_window();
  if (!w) return;
  const auto width = static_cast<std::size_t>(w->record_width);
  window_head_ = (window_head_ + 1) % static_cast<std::size_t>(w->records);
  const std::span<std::uint16_t> slot(window_ring_.data() + window_head_ * width, width);
  // A value the encoding cannot carry (an overload beyond the type) keeps the slot's old words,
  // as publish() keeps a register's last value; the counter still moves on in a fresh slot.
  (void)protocols::encode_record(map_, *w, m, slot);
  window_filled_ = std::min(window_filled_ + 1, static_cast<std::size_t>(w->records));
  window_dirty_ = true;
}

}  // namespace hystlab::sim
