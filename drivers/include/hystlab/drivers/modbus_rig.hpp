#pragma once
// A rig over Modbus (libmodbus): TCP, or RTU on a serial device. Signals come from a
// RegisterMap; one read per table fetches a whole sample.
#include <memory>
#include <string>
#include <vector>

#include "hystlab/drivers/rig.hpp"
#include "hystlab/protocols/register_map.hpp"
#include "hystlab/protocols/sample_record.hpp"

struct _modbus;  // libmodbus context

namespace hystlab::drivers {

struct ModbusRigConfig {
  enum class Transport { tcp, rtu } transport = Transport::tcp;
  std::string host = "127.0.0.1";
  int port = 502;
  std::string device;  // RTU: /dev/ttyUSB0, or a pty slave path
  int baud = 115200;
  char parity = 'N';
  int data_bits = 8, stop_bits = 1;
  int slave = 0;                                         // 0: the map's slave_id
  double response_timeout_s = 0.05;                      // whole answer
  double byte_timeout_s = 0.01;                          // between bytes of one answer
  double reconnect_min_s = 0.05, reconnect_max_s = 2.0;  // back-off, doubling
  double stale_after_s = 0.5;                            // sample counter unchanged this long: stale_data
  bool block_reads = false;                              // read_samples()/read_shaker_samples() read the map's sample_window (required then)
  protocols::RegisterMap map;
  std::string name = "modbus rig";
};

class ModbusRig final : public Rig {
 public:
  explicit ModbusRig(ModbusRigConfig config);
  ~ModbusRig() override;
  ModbusRig(const ModbusRig&) = delete;
  ModbusRig& operator=(const ModbusRig&) = delete;

  std::error_code connect(double now_s) noexcept override;
  void disconnect() noexcept override;
  std::error_code arm(bool enable) noexcept override;
  std::error_code command(double setpoint_mm, double ramp_rate_mm_s) noexcept override;
  std::error_code hold(bool on) noexcept override;
  std::error_code estop(bool on) noexcept override;
  std::error_code set_mode(std::uint16_t mode) noexcept override;
  std::error_code reset_faults() noexcept override;
  std::error_code write_host_heartbeat(std::uint32_t value) noexcept override;
  [[nodiscard]] std::string fault_text(std::uint16_t code) const override { return cfg_.map.fault_text(code); }
  std::error_code read_sample(double now_s, RigSample& out) noexcept override;
  std::error_code read_samples(double now_s, std::vector<RigSample>& out) noexcept override;
  [[nodiscard]] bool block_reads() const noexcept override { return cfg_.block_reads; }
  std::error_code command_shaker(double frequency_hz, double amplitude_mm, bool enable) noexcept override;
  std::error_code read_shaker(double now_s, ShakerSample& out) noexcept override;
  std::error_code read_shaker_samples(double now_s, std::vector<ShakerSample>& out) noexcept override;
  [[nodiscard]] IoHealthSnapshot health() const noexcept override { return health_.snapshot(); }
  [[nodiscard]] std::string describe() const override;

 private:
  struct Write {
    protocols::Signal signal;
    double value;
  };
  std::error_code write_signals(std::initializer_list<Write> writes) noexcept;
  std::error_code read_blocks(double now_s) noexcept;  // fills words_/bits_ from the map's blocks
  std::error_code value_of(protocols::Signal s, double& v) const noexcept;
  std::error_code ensure_connected(double now_s) noexcept;
  std::error_code fail(int err, const char* op) noexcept;  // classify errno, count, log once per episode
  void resync() noexcept;                                  // after a timeout or a broken answer: no late answer may follow
  void drain_line() noexcept;
  void back_off() noexcept;
  void succeed() noexcept;
  std::error_code check_stale(double now_s, std::uint32_t counter) noexcept;
  std::error_code read_window_page(int first, int count) noexcept;
  std::error_code take_window(double now_s, int& fresh, bool& reached) noexcept;
  std::error_code take_fresh(double now_s, int& fresh) noexcept;  // the window's fresh records, a gap counted
  double record_time(std::uint32_t counter) noexcept;             // the controller's clock, record by record
  void emit_window(int fresh, std::vector<RigSample>& out) noexcept;
  void emit_window(int fresh, std::vector<ShakerSample>& out) noexcept;

  ModbusRigConfig cfg_;
  _modbus* ctx_ = nullptr;
  bool connected_ = false;
  double last_now_ = 0, next_attempt_ = 0, backoff_ = 0;
  std::vector<std::vector<std::uint16_t>> block_words_;
  IoHealth health_;
  int episode_ = 0;  // RigError of the current error episode, 0 when healthy
  std::uint64_t episode_count_ = 0;
  std::uint32_t last_counter_ = 0;
  double counter_changed_at_ = -1;
  // Block reads: the window's words and decoded records (newest first), and the controller's
  // clock: the last counter taken, extended to 64 bits, and the host time it was anchored at.
  std::vector<std::uint16_t> window_words_;
  std::vector<protocols::SignalArray> window_records_;
  bool have_window_counter_ = false;
  std::uint32_t window_counter_ = 0;
  std::int64_t window_counter64_ = 0, anchor_counter64_ = 0;
  double anchor_time_s_ = 0;
  // Polled shaker samples on the controller's clock (the map's sample_period_s): the counter at
  // the anchor, extended to 64 bits, and the host time then.
  double clock_time(double now_s, std::uint32_t counter) noexcept;
  bool have_poll_anchor_ = false;
  std::uint32_t poll_counter_ = 0;
  std::int64_t poll_counter64_ = 0, poll_anchor64_ = 0;
  double poll_anchor_s_ = 0;
  // The shaker's enable as last written: a drive write rewrites it only when it changes (or
  // after anything that can have changed it on the controller: a reconnect, an error, an
  // e-stop, a reset), so a running sweep's drive writes are the drive alone.
  bool enable_known_ = false, enable_written_ = false;
};

}  // namespace hystlab::drivers
