#pragma once
// A Modbus register map as data: which table, address, type, word order and scaling carry each
// signal. Real controllers differ, so the map is a JSON file (docs: protocols/MODBUS.md).
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "hystlab/protocols/protocol_error.hpp"
#include "hystlab/protocols/signals.hpp"

namespace hystlab::protocols {

enum class ModbusTable { coil, discrete_input, holding_register, input_register };
enum class ValueType { boolean, int16, uint16, int32, uint32, float32 };
enum class WordOrder { big, swapped };  // 32-bit values: high word first, or low word first

struct MapEntry {
  Signal signal{};
  ModbusTable table{};
  std::uint16_t address = 0;
  ValueType type = ValueType::uint16;
  WordOrder word_order = WordOrder::big;
  double scale = 1.0;  // engineering = raw * scale + offset
  double offset = 0.0;
  std::string unit;
  std::optional<double> min, max;            // engineering limits; a decoded value outside is out_of_range
  [[nodiscard]] int width() const noexcept;  // registers (or bits) used: 1 or 2
};

// A controller that samples on its own clock and keeps its newest samples in a window of
// registers, newest first: the host reads whole blocks of samples, so a late poll loses nothing
// and every sample carries the controller's time (sample_counter x period_s). Optional.
struct SampleWindow {
  ModbusTable table = ModbusTable::input_register;
  std::uint16_t address = 0;   // record 0 (the newest) starts here
  int records = 0;             // depth of the window
  double period_s = 0;         // the controller's sample period
  std::vector<Signal> fields;  // one record: these signals, each encoded as its entry says
  int record_width = 0;        // registers per record
  [[nodiscard]] int records_per_read() const noexcept { return 125 / record_width; }
};

struct MapError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// One contiguous read per table covering every measurement it holds.
struct ReadBlock {
  ModbusTable table{};
  std::uint16_t start = 0;
  std::uint16_t count = 0;
};

class RegisterMap {
 public:
  // Throws MapError naming the field: unknown signal/type/table/word order, overlapping
  // addresses, a missing required signal, a scale of 0, a bool in a register table, ...
  static RegisterMap from_json(std::string_view text);

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] RigKind kind() const noexcept { return kind_; }
  [[nodiscard]] int slave_id() const noexcept { return slave_id_; }
  [[nodiscard]] const MapEntry* find(Signal s) const noexcept;
  [[nodiscard]] const std::vector<MapEntry>& entries() const noexcept { return entries_; }
  // Blocks covering the measurements (reads) of this map.
  [[nodiscard]] const std::vector<ReadBlock>& measurement_blocks() const noexcept { return blocks_; }
  [[nodiscard]] const std::optional<SampleWindow>& sample_window() const noexcept { return window_; }
  // The controller's sample clock: its sample_counter advances once per period (the map's
  // optional `sample_period_s`, else its window's period); 0 when the map does not say.
  [[nodiscard]] double sample_period_s() const noexcept { return period_s_ > 0 ? period_s_ : window_ ? window_->period_s : 0.0; }
  // The controller's text for a fault code (the map's optional `fault_codes`); empty if unknown.
  [[nodiscard]] std::string fault_text(std::uint16_t code) const;
  [[nodiscard]] const std::map<std::uint16_t, std::string>& fault_codes() const noexcept { return fault_codes_; }

 private:
  static RegisterMap parse_map(std::string_view text);
  std::string name_;
  RigKind kind_ = RigKind::load_frame;
  int slave_id_ = 1;
  std::vector<MapEntry> entries_;
  std::array<int, kSignalCount> index_{};
  std::vector<ReadBlock> blocks_;
  std::optional<SampleWindow> window_;
  double period_s_ = 0;
  std::map<std::uint16_t, std::string> fault_codes_;
};

// Engineering value -> register words (1 or 2) or a bit (0/1 in words[0]).
std::error_code encode(const MapEntry& e, double value, std::span<std::uint16_t> words) noexcept;
// Register words (or a bit) -> engineering value, checked against the entry's limits.
std::error_code decode(const MapEntry& e, std::span<const std::uint16_t> words, double& value) noexcept;

}  // namespace hystlab::protocols
