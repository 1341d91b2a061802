#pragma once
// The simulator's Modbus side: a libmodbus server over TCP (many clients) or RTU on a pty,
// whose registers are the rig's signals encoded with the register map.
#include <cstdint>
#include <string>
#include <vector>

#include "hystlab/protocols/register_map.hpp"
#include "sim_rig.hpp"

struct _modbus;
struct _modbus_mapping_t;

namespace hystlab::sim {

class ModbusEndpoint {
 public:
  enum class Transport { tcp, rtu };
  // tcp: listens on address:port (0: any free port); rtu: opens a pty pair.
  ModbusEndpoint(Transport t, const std::string& address, int port, protocols::RegisterMap map);
  ~ModbusEndpoint();
  ModbusEndpoint(const ModbusEndpoint&) = delete;
  ModbusEndpoint& operator=(const ModbusEndpoint&) = delete;

  [[nodiscard]] std::string where() const;  // "modbus-tcp 127.0.0.1:1502" or "modbus-rtu /dev/pts/3"
  void fds(std::vector<int>& out) const;    // to wait on
  // Handles whatever is ready on fd; returns the commands written (NaN where none).
  void handle(int fd, const Faults& faults, SimRig& rig);
  void publish(const SignalValues& measurements);
  // One sample of the controller's clock into the map's sample window (if it has one); the
  // window's registers change at the next publish().
  void record(const SignalValues& measurements);
  void drop_clients();

 private:
  void serve(int fd, const Faults& faults, SimRig& rig);
  void show_enable(const SimRig& rig);
  [[nodiscard]] bool starts_new_step(const std::uint8_t* query, int length);
  void reply_with_bad_crc(const std::uint8_t* query, int length);
  SignalValues written_commands() const;

  Transport transport_;
  protocols::RegisterMap map_;
  _modbus* ctx_ = nullptr;
  _modbus_mapping_t* mapping_ = nullptr;
  int listen_fd_ = -1, pty_master_ = -1, pty_slave_ = -1;
  std::string address_, pty_path_;
  int port_ = 0;
  std::vector<int> clients_;
  std::vector<std::uint16_t> window_ring_;  // encoded records, oldest overwritten first
  std::size_t window_head_ = 0, window_filled_ = 0;
  bool window_dirty_ = false;
  double last_late_hz_ = 0;  // the late-step fault's last step
};

}  // namespace hystlab::sim
