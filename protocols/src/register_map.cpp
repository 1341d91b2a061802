#include "hystlab/protocols/register_map.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>

namespace hystlab::protocols {
namespace {
using nlohmann::json;

[[noreturn]] void fail(const std::string& msg) { throw MapError("register map: " + msg); }

bool is_bit_table(ModbusTable t) { return t == ModbusTable::coil || t == ModbusTable::discrete_input; }

const char* table_name(ModbusTable t) {
  switch (t) {
    case ModbusTable::coil:
      return "coil";
    case ModbusTable::discrete_input:
      return "discrete_input";
    case ModbusTable::holding_register:
      return "holding_register";
    case ModbusTable::input_register:
      return "input_register";
  }
  return "?";
}

template <class E>
E pick(const json& v, const std::string& where, const std::vector<std::pair<const char*, E>>& options) {
  std::string known;
  if (v.is_string())
    for (const auto& [n, e] : options)
      if (v.get<std::string>() == n) return e;
  for (const auto& [n, e] : options) known += (known.empty() ? "" : ", ") + std::string(n);
  fail(where + " is " + v.dump() + ", expected one of: " + known);
}

double finite_number(const json& v, const std::string& where) {
  if (!v.is_number() || !std::isfinite(v.get<double>())) fail(where + " must be a finite number");
  return v.get<double>();
}

std::uint16_t parse_address(const json& j, const std::string& where) {
  if (!j.is_number_integer() || j.get<long long>() < 0 || j.get<long long>() > 65535) fail(where + " must be an integer from 0 to 65535");
  return static_cast<std::uint16_t>(j.get<long long>());
}

MapEntry parse_entry(Signal s, const json& j) {
  const std::string where = "signals." + std::string(signal_name(s));
  if (!j.is_object()) fail(where + " must be an object");
  for (const auto& [key, _] : j.items())
    if (key != "table" && key != "address" && key != "type" && key != "word_order" && key != "scale" && key != "offset" && key != "unit" && key != "min" &&
        key != "max")
      fail(where + " has an unknown field '" + key + "'");
  MapEntry e;
  e.signal = s;
  if (!j.contains("table")) fail(where + ".table is missing");
  e.table = pick<ModbusTable>(j["table"], where + ".table",
                              {{"coil", ModbusTable::coil},
                               {"discrete_input", ModbusTable::discrete_input},
                               {"holding_register", ModbusTable::holding_register},
                               {"input_register", ModbusTable::input_register}});
  if (!j.contains("address")) fail(where + ".address must be an integer from 0 to 65535");
  e.address = parse_address(j["address"], where + ".address");
  const json type = j.value("type", json(is_bit_table(e.table) ? "bool" : "uint16"));
  e.type = pick<ValueType>(type, where + ".type",
                           {{"bool", ValueType::boolean},
                            {"int16", ValueType::int16},
                            {"uint16", ValueType::uint16},
                            {"int32", ValueType::int32},
                            {"uint32", ValueType::uint32},
                            {"float32", ValueType::float32}});
  if (is_bit_table(e.table) != (e.type == ValueType::boolean))
    fail(where + ".type " + type.dump() + " does not fit table '" + table_name(e.table) + "' (coils and discrete inputs are bool, registers are numbers)");
  if (j.contains("word_order"))
    e.word_order = pick<WordOrder>(j["word_order"], where + ".word_order", {{"big", WordOrder::big}, {"swapped", WordOrder::swapped}});
  if (j.contains("scale")) e.scale = finite_number(j["scale"], where + ".scale");
  if (e.scale == 0.0) fail(where + ".scale must not be 0");
  if (j.contains("offset")) e.offset = finite_number(j["offset"], where + ".offset");
  if (j.contains("unit")) e.unit = j["unit"].is_string() ? j["unit"].get<std::string>() : "";
  if (j.contains("min")) e.min = finite_number(j["min"], where + ".min");
  if (j.contains("max")) e.max = finite_number(j["max"], where + ".max");
  if (e.min && e.max && !(*e.min < *e.max)) fail(where + ".min must be below .max");
  if (is_command(s) ? e.table == ModbusTable::discrete_input || e.table == ModbusTable::input_register : false)
    fail(where + " is a command: it must be in a writable table (coil or holding_register)");
  if (static_cast<int>(e.address) + e.width() > 65536) fail(where + " runs past address 65535");
  // A reset is a pulse the controller sees as an edge: a bit. A heartbeat is a counter.
  if (s == Signal::fault_reset && e.table != ModbusTable::coil) fail(where + " must be a coil (a reset is a bit the host pulses)");
  if (s == Signal::host_heartbeat && (e.table != ModbusTable::holding_register || (e.type != ValueType::uint16 && e.type != ValueType::uint32)))
    fail(where + " must be a holding_register of type uint16 or uint32 (a counter the host writes)");
  return e;
}

// The optional "fault_codes": {"1": "displacement limit tripped", ...}, decimal codes 1..65535.
std::map<std::uint16_t, std::string> parse_fault_codes(const json& j) {
  if (!j.is_object()) fail("fault_codes must be an object from fault codes (\"1\" to \"65535\") to texts");
  std::map<std::uint16_t, std::string> codes;
  for (const auto& [key, text] : j.items()) {
    const std::string where = "fault_codes.\"" + key + "\"";
    const bool digits = !key.empty() && key.size() <= 5 && key.find_first_not_of("0123456789") == std::string::npos && key[0] != '0';
    if (!digits || std::stol(key) > 65535) fail(where + ": the code must be a decimal integer from 1 to 65535");
    if (!text.is_string() || text.get<std::string>().empty()) fail(where + " must be a non-empty string");
    codes[static_cast<std::uint16_t>(std::stol(key))] = text.get<std::string>();
  }
  return codes;
}

// The optional "sample_window": where, how deep, at what period, and which signals a record holds.
SampleWindow parse_window(const json& j, const RegisterMap& m) {
  const std::string where = "sample_window";
  if (!j.is_object()) fail(where + " must be an object");
  for (const auto& [key, _] : j.items())
    if (key != "table" && key != "address" && key != "records" && key != "period_s" && key != "fields") fail(where + " has an unknown field '" + key + "'");
  SampleWindow w;
  w.table = pick<ModbusTable>(j.value("table", json("input_register")), where + ".table",
                              {{"holding_register", ModbusTable::holding_register}, {"input_register", ModbusTable::input_register}});
  if (!j.contains("address")) fail(where + ".address is missing");
  w.address = parse_address(j["address"], where + ".address");
  if (!j.contains("records") || !j["records"].is_number_integer() || j["records"].get<long long>() < 1 || j["records"].get<long long>() > 10000)
    fail(where + ".records must be an integer from 1 to 10000");
  w.records = j["records"].get<int>();
  if (!j.contains("period_s")) fail(where + ".period_s is missing");
  w.period_s = finite_number(j["period_s"], where + ".period_s");
  if (!(w.period_s > 0)) fail(where + ".period_s must be > 0");
  if (!j.contains("fields") || !j["fields"].is_array() || j["fields"].empty()) fail(where + ".fields must be a non-empty array of signal names");
  for (const json& f : j["fields"]) {
    const auto s = f.is_string() ? signal_from_name(f.get<std::string>()) : std::nullopt;
    if (!s) fail(where + ".fields has " + f.dump() + ", which is not a signal");
    const MapEntry* e = m.find(*s);
    if (!e) fail(where + ".fields has '" + f.get<std::string>() + "', which 'signals' does not define (its encoding comes from there)");
    if (is_command(*s) || e->type == ValueType::boolean) fail(where + ".fields has '" + f.get<std::string>() + "', which is not a register measurement");
    if (std::find(w.fields.begin(), w.fields.end(), *s) != w.fields.end()) fail(where + ".fields has '" + f.get<std::string>() + "' twice");
    w.fields.push_back(*s);
    w.record_width += e->width();
  }
  if (std::find(w.fields.begin(), w.fields.end(), Signal::sample_counter) == w.fields.end())
    fail(where + ".fields must hold sample_counter (a record's time is its counter x period_s)");
  if (w.record_width > 125) fail(where + ": a record of " + std::to_string(w.record_width) + " registers does not fit in one Modbus read (125)");
  const long end = static_cast<long>(w.address) + static_cast<long>(w.records) * w.record_width;
  if (end > 65536) fail(where + " runs past address 65535");
  for (const MapEntry& e : m.entries())
    if (e.table == w.table && e.address + e.width() > w.address && e.address < end)
      fail(where + " overlaps signals." + std::string(signal_name(e.signal)) + " at " + table_name(e.table) + " " + std::to_string(e.address));
  return w;
}

}  // namespace

int MapEntry::width() const noexcept { return type == ValueType::int32 || type == ValueType::uint32 || type == ValueType::float32 ? 2 : 1; }

RegisterMap RegisterMap::from_json(std::string_view text) {
  try {
    return parse_map(text);
  } catch (const json::exception& e) {  // a number too large, a field of the wrong type, ...
    fail(std::string("malformed (") + e.what() + ")");
  }
}

namespace {
// The optional "sample_period_s": the controller's sample clock (one with the window's, if any).
double parse_sample_period(const json& p, const std::optional<SampleWindow>& window) {
  if (!p.is_number() || !(p.get<double>() > 0) || p.get<double>() > 1) fail("sample_period_s must be a number of seconds > 0 and <= 1");
  const double s = p.get<double>();
  if (window && std::fabs(window->period_s - s) > 1e-12 * s) fail("sample_period_s differs from sample_window.period_s: the controller has one sample clock");
  return s;
}
}  // namespace

RegisterMap RegisterMap::parse_map(std::string_view text) {
  json j;
  try {
    j = json::parse(text.begin(), text.end());
  } catch (const json::parse_error& e) {
    fail(std::string("not valid JSON (") + e.what() + ")");
  }
  if (!j.is_object()) fail("the document is not a JSON object");
  if (!j.contains("format") || j["format"] != "hystlab-modbus-map") fail("'format' must be \"hystlab-modbus-map\"");
  if (!j.contains("version") || j["version"] != 1) fail("unknown version " + j.value("version", json()).dump() + " (this hystlab reads version 1)");
  RegisterMap m;
  m.name_ = j.contains("name") && j["name"].is_string() ? j["name"].get<std::string>() : "unnamed";
  if (j.contains("rig")) m.kind_ = pick<RigKind>(j["rig"], "rig", {{"load_frame", RigKind::load_frame}, {"shaker", RigKind::shaker}});
  if (j.contains("slave_id")) {
    if (!j["slave_id"].is_number_integer() || j["slave_id"] < 1 || j["slave_id"] > 247) fail("slave_id must be from 1 to 247");
    m.slave_id_ = j["slave_id"].get<int>();
  }
  if (!j.contains("signals") || !j["signals"].is_object()) fail("'signals' must be an object");
  m.index_.fill(-1);
  for (const auto& [key, value] : j["signals"].items()) {
    const auto s = signal_from_name(key);
    if (!s) fail("unknown signal 'signals." + key + "'");
    m.index_[static_cast<std::size_t>(*s)] = static_cast<int>(m.entries_.size());
    m.entries_.push_back(parse_entry(*s, value));
  }
  for (std::size_t k = 0; k < kSignalCount; ++k)
    if (is_required(static_cast<Signal>(k), m.kind_) && m.index_[k] < 0)
      fail("missing required signal 'signals." + std::string(signal_name(static_cast<Signal>(k))) + "'");
  // Overlaps: every register (or bit) of a table belongs to one signal.
  std::map<std::pair<int, int>, Signal> used;
  for (const MapEntry& e : m.entries_)
    for (int w = 0; w < e.width(); ++w) {
      const auto key = std::make_pair(static_cast<int>(e.table), e.address + w);
      if (const auto it = used.find(key); it != used.end())
        fail("signals." + std::string(signal_name(e.signal)) + " overlaps signals." + std::string(signal_name(it->second)) + " at " + table_name(e.table) +
             " " + std::to_string(e.address + w));
      used[key] = e.signal;
    }
  for (const ModbusTable t : {ModbusTable::input_register, ModbusTable::holding_register, ModbusTable::discrete_input, ModbusTable::coil}) {
    int lo = 65536, hi = -1;
    for (const MapEntry& e : m.entries_)
      if (e.table == t && !is_command(e.signal)) {
        lo = std::min(lo, static_cast<int>(e.address));
        hi = std::max(hi, e.address + e.width() - 1);
      }
    if (hi < 0) continue;
    if (hi - lo + 1 > (is_bit_table(t) ? 2000 : 125)) fail(std::string("measurements in ") + table_name(t) + " span more than one Modbus read");
    m.blocks_.push_back(ReadBlock{t, static_cast<std::uint16_t>(lo), static_cast<std::uint16_t>(hi - lo + 1)});
  }
  if (j.contains("sample_window")) m.window_ = parse_window(j["sample_window"], m);
  if (j.contains("fault_codes")) m.fault_codes_ = parse_fault_codes(j["fault_codes"]);
  if (j.contains("sample_period_s")) m.period_s_ = parse_sample_period(j["sample_period_s"], m.window_);
  return m;
}

std::string RegisterMap::fault_text(std::uint16_t code) const {
  const auto it = fault_codes_.find(code);
  return it == fault_codes_.end() ? std::string{} : it->second;
}

const MapEntry* RegisterMap::find(Signal s) const noexcept {
  const int i = index_[static_cast<std::size_t>(s)];
  return i < 0 ? nullptr : &entries_[static_cast<std::size_t>(i)];
}

std::error_code encode(const MapEntry& e, double value, std::span<std::uint16_t> words) noexcept {
  if (!std::isfinite(value)) return ProtocolError::not_finite;
  if (words.size() < static_cast<std::size_t>(e.width())) return ProtocolError::wrong_length;
  const double raw = (value - e.offset) / e.scale;
  std::uint32_t bits = 0;
  auto in = [&](double lo, double hi) { return raw >= lo && raw <= hi; };
  switch (e.type) {
    case ValueType::boolean:
      words[0] = raw != 0.0 ? 1 : 0;
      return {};
    case ValueType::int16:
      if (!in(-32768.5, 32767.49)) return ProtocolError::out_of_range;
      words[0] = static_cast<std::uint16_t>(static_cast<std::int16_t>(std::lround(raw)));
      return {};
    case ValueType::uint16:
      if (!in(-0.5, 65535.49)) return ProtocolError::out_of_range;
      words[0] = static_cast<std::uint16_t>(std::lround(raw));
      return {};
    case ValueType::int32:
      if (!in(-2147483648.5, 2147483647.49)) return ProtocolError::out_of_range;
      bits = static_cast<std::uint32_t>(static_cast<std::int32_t>(std::llround(raw)));
      break;
    case ValueType::uint32:
      if (!in(-0.5, 4294967295.49)) return ProtocolError::out_of_range;
      bits = static_cast<std::uint32_t>(std::llround(raw));
      break;
    case ValueType::float32: {
      if (std::fabs(raw) > static_cast<double>(std::numeric_limits<float>::max())) return ProtocolError::out_of_range;
      bits = std::bit_cast<std::uint32_t>(static_cast<float>(raw));
      break;
    }
  }
  const auto hi = static_cast<std::uint16_t>(bits >> 16), lo = static_cast<std::uint16_t>(bits & 0xFFFFU);
  words[0] = e.word_order == WordOrder::big ? hi : lo;
  words[1] = e.word_order == WordOrder::big ? lo : hi;
  return {};
}

std::error_code decode(const MapEntry& e, std::span<const std::uint16_t> words, double& value) noexcept {
  if (words.size() < static_cast<std::size_t>(e.width())) return ProtocolError::wrong_length;
  double raw = 0.0;
  const std::uint32_t bits =
      e.width() == 2 ? (e.word_order == WordOrder::big ? (std::uint32_t{words[0]} << 16) | words[1] : (std::uint32_t{words[1]} << 16) | words[0]) : words[0];
  switch (e.type) {
    case ValueType::boolean:
      raw = words[0] != 0 ? 1.0 : 0.0;
      break;
    case ValueType::int16:
      raw = static_cast<std::int16_t>(words[0]);
      break;
    case ValueType::uint16:
      raw = words[0];
      break;
    case ValueType::int32:
      raw = static_cast<std::int32_t>(bits);
      break;
    case ValueType::uint32:
      raw = bits;
      break;
    case ValueType::float32:
      raw = static_cast<double>(std::bit_cast<float>(bits));
      break;
  }
  if (!std::isfinite(raw)) return ProtocolError::not_finite;
  const double v = raw * e.scale + e.offset;
  if ((e.min && v < *e.min) || (e.max && v > *e.max)) return ProtocolError::out_of_range;
  value = v;
  return {};
}

}  // namespace hystlab::protocols
