#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "../support/build_paths.hpp"
#include "hystlab/protocols/can_protocol.hpp"
#include "hystlab/protocols/modbus_crc.hpp"
#include "hystlab/protocols/register_map.hpp"
#include "hystlab/protocols/sample_record.hpp"

using namespace hystlab::protocols;

namespace {
std::string slurp(const std::string& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}
MapEntry entry(ValueType t, WordOrder w = WordOrder::big, double scale = 1, double offset = 0) {
  MapEntry e;
  e.table = ModbusTable::holding_register;
  e.type = t;
  e.word_order = w;
  e.scale = scale;
  e.offset = offset;
  return e;
}
std::array<std::uint16_t, 2> enc(const MapEntry& e, double v) {
  std::array<std::uint16_t, 2> w{0xDEAD, 0xBEEF};
  REQUIRE_FALSE(encode(e, v, w));
  return w;
}
double dec(const MapEntry& e, std::array<std::uint16_t, 2> w) {
  double v = 0;
  REQUIRE_FALSE(decode(e, w, v));
  return v;
}
// The shipped load frame map, changed by mutate, must be refused with needle in the message.
template <class Mutate>
void refused_after(Mutate mutate, const char* needle) {
  auto j = nlohmann::json::parse(slurp(HYSTLAB_MAPS + "/default_load_frame.json"));
  mutate(j);
  CAPTURE(needle);
  CHECK_THROWS_WITH_AS((void)RegisterMap::from_json(j.dump()), doctest::Contains(needle), MapError);
}
}  // namespace

TEST_CASE("register encoding: every type and word order, byte for byte") {
  CHECK(enc(entry(ValueType::uint16), 4660)[0] == 0x1234);
  CHECK(enc(entry(ValueType::int16), -2)[0] == 0xFFFE);
  CHECK(dec(entry(ValueType::int16), {0x8000, 0}) == -32768);
  CHECK(enc(entry(ValueType::int32), -2) == std::array<std::uint16_t, 2>{0xFFFF, 0xFFFE});
  CHECK(enc(entry(ValueType::int32, WordOrder::swapped), -2) == std::array<std::uint16_t, 2>{0xFFFE, 0xFFFF});
  CHECK(enc(entry(ValueType::uint32), 0x12345678) == std::array<std::uint16_t, 2>{0x1234, 0x5678});
  CHECK(enc(entry(ValueType::uint32, WordOrder::swapped), 0x12345678) == std::array<std::uint16_t, 2>{0x5678, 0x1234});
  // 1.5f = 0x3FC00000
  CHECK(enc(entry(ValueType::float32), 1.5) == std::array<std::uint16_t, 2>{0x3FC0, 0x0000});
  CHECK(enc(entry(ValueType::float32, WordOrder::swapped), 1.5) == std::array<std::uint16_t, 2>{0x0000, 0x3FC0});
  CHECK(dec(entry(ValueType::float32), {0xC020, 0x0000}) == -2.5);
  CHECK(dec(entry(ValueType::float32, WordOrder::swapped), {0x0000, 0xC020}) == -2.5);
  // scaled integers: 12.345 mm in µm
  CHECK(enc(entry(ValueType::int32, WordOrder::swapped, 0.001), 12.345) == std::array<std::uint16_t, 2>{12345, 0});
  CHECK(dec(entry(ValueType::int32, WordOrder::swapped, 0.001), {12345, 0}) == doctest::Approx(12.345));
  CHECK(enc(entry(ValueType::uint16, WordOrder::big, 0.1, 100), 150)[0] == 500);  // (150-100)/0.1
  CHECK(dec(entry(ValueType::uint16, WordOrder::big, 0.1, 100), {500, 0}) == doctest::Approx(150));
}

TEST_CASE("register encoding: range and finiteness are typed errors") {
  std::array<std::uint16_t, 2> w{};
  CHECK(encode(entry(ValueType::uint16), -1, w) == ProtocolError::out_of_range);
  CHECK(encode(entry(ValueType::int16), 40000, w) == ProtocolError::out_of_range);
  CHECK(encode(entry(ValueType::int32, WordOrder::big, 0.001), 3e6, w) == ProtocolError::out_of_range);
  CHECK(encode(entry(ValueType::float32), NAN, w) == ProtocolError::not_finite);
  MapEntry lim = entry(ValueType::float32);
  lim.max = 10;
  double v = 0;
  CHECK(decode(lim, std::array<std::uint16_t, 2>{0x4130, 0}, v) == ProtocolError::out_of_range);  // 11.0
  CHECK(decode(entry(ValueType::float32), std::array<std::uint16_t, 2>{0x7FC0, 0}, v) == ProtocolError::not_finite);
  CHECK(decode(entry(ValueType::int32), std::array<std::uint16_t, 1>{1}, v) == ProtocolError::wrong_length);
}

TEST_CASE("register maps: the shipped maps load, with their read blocks") {
  const RegisterMap a = RegisterMap::from_json(slurp(HYSTLAB_MAPS + "/default_load_frame.json"));
  CHECK(a.slave_id() == 1);
  REQUIRE(a.find(Signal::force_N));
  CHECK(a.find(Signal::force_N)->address == 2);
  REQUIRE(a.measurement_blocks().size() == 1);
  CHECK(a.measurement_blocks()[0].count == 12);
  const RegisterMap b = RegisterMap::from_json(slurp(HYSTLAB_MAPS + "/vendor_b_load_frame.json"));
  CHECK(b.find(Signal::displacement_mm)->word_order == WordOrder::swapped);
  CHECK(b.measurement_blocks()[0].start == 3000);
  const RegisterMap s = RegisterMap::from_json(slurp(HYSTLAB_MAPS + "/default_shaker.json"));
  CHECK(s.kind() == RigKind::shaker);
}

TEST_CASE("register maps: a bad map is rejected with the field named") {
  refused_after([](auto& j) { j["signals"]["force_N"]["address"] = 1; }, "overlaps");
  refused_after([](auto& j) { j["signals"]["force_N"]["type"] = "float64"; }, "signals.force_N.type");
  refused_after([](auto& j) { j["signals"].erase("sample_counter"); }, "missing required signal 'signals.sample_counter'");
  refused_after([](auto& j) { j["signals"]["force_N"]["scale"] = 0; }, "signals.force_N.scale must not be 0");
  refused_after([](auto& j) { j["signals"]["torque"] = j["signals"]["force_N"]; }, "unknown signal 'signals.torque'");
  refused_after([](auto& j) { j["signals"]["enable"]["type"] = "uint16"; }, "does not fit table 'coil'");
  refused_after([](auto& j) { j["signals"]["setpoint_mm"]["table"] = "input_register"; }, "writable table");
  refused_after([](auto& j) { j["signals"]["force_N"]["word_order"] = "little"; }, "signals.force_N.word_order");
  refused_after([](auto& j) { j["version"] = 9; }, "unknown version 9");
  CHECK_THROWS_WITH_AS((void)RegisterMap::from_json("{oops"), doctest::Contains("not valid JSON"), MapError);
  // found by the fuzzer: numbers too large for a double, fields of the wrong type
  CHECK_THROWS_AS((void)RegisterMap::from_json(R"({"format": "hystlab-modbus-map", "version": 6e666})"), MapError);
  CHECK_THROWS_AS((void)RegisterMap::from_json(R"({"format": 3, "version": 1})"), MapError);
  refused_after(
      [](auto& j) {
        j["name"] = 7;
        j["signals"]["force_N"]["unit"] = 3;
        j["signals"]["force_N"]["address"] = "two";
      },
      "signals.force_N.address");
}

TEST_CASE("register maps: the controller signals fault_reset and host_heartbeat, and fault_codes") {
  const RegisterMap a = RegisterMap::from_json(slurp(HYSTLAB_MAPS + "/default_load_frame.json"));
  REQUIRE(a.find(Signal::fault_reset));
  CHECK(a.find(Signal::fault_reset)->table == ModbusTable::coil);
  CHECK(a.find(Signal::fault_reset)->address == 3);
  REQUIRE(a.find(Signal::host_heartbeat));
  CHECK(a.find(Signal::host_heartbeat)->address == 5);
  CHECK(is_command(Signal::fault_reset));
  CHECK(is_command(Signal::host_heartbeat));
  CHECK_FALSE(is_command(Signal::displacement_mm));
  CHECK_FALSE(is_required(Signal::fault_reset, RigKind::load_frame));
  CHECK_FALSE(is_required(Signal::host_heartbeat, RigKind::shaker));
  for (std::size_t k = 0; k < kSignalCount; ++k) CHECK(signal_from_name(signal_name(static_cast<Signal>(k))) == static_cast<Signal>(k));
  CHECK(a.fault_text(1) == "displacement limit tripped");
  CHECK(a.fault_text(4) == "host heartbeat lost");
  CHECK(a.fault_text(7).empty());
  CHECK(a.fault_text(0).empty());
  const RegisterMap s = RegisterMap::from_json(slurp(HYSTLAB_MAPS + "/default_shaker.json"));
  CHECK(s.find(Signal::fault_reset)->address == 2);
  CHECK(s.fault_text(3) == "e-stop pressed");
  const RegisterMap b = RegisterMap::from_json(slurp(HYSTLAB_MAPS + "/vendor_b_load_frame.json"));
  CHECK(b.find(Signal::fault_reset)->address == 19);
  CHECK_FALSE(b.find(Signal::host_heartbeat));
  CHECK(b.fault_text(1).empty());  // no fault_codes: no texts
  // A map without the optional controller signals still loads.
  auto j = nlohmann::json::parse(slurp(HYSTLAB_MAPS + "/default_load_frame.json"));
  j["signals"].erase("fault_reset");
  j["signals"].erase("host_heartbeat");
  j.erase("fault_codes");
  CHECK_FALSE(RegisterMap::from_json(j.dump()).find(Signal::fault_reset));
}

TEST_CASE("register maps: bad fault_codes, fault_reset or host_heartbeat are refused with the field named") {
  refused_after([](auto& j) { j["fault_codes"] = nlohmann::json::array({"x"}); }, "fault_codes must be an object");
  refused_after([](auto& j) { j["fault_codes"]["zero"] = "text"; }, "fault_codes.\"zero\": the code must be a decimal integer from 1 to 65535");
  refused_after([](auto& j) { j["fault_codes"]["0"] = "text"; }, "fault_codes.\"0\": the code must be a decimal integer");
  refused_after([](auto& j) { j["fault_codes"]["65536"] = "text"; }, "fault_codes.\"65536\": the code must be a decimal integer");
  refused_after([](auto& j) { j["fault_codes"]["-3"] = "text"; }, "fault_codes.\"-3\": the code must be a decimal integer");
  refused_after([](auto& j) { j["fault_codes"]["1.5"] = "text"; }, "fault_codes.\"1.5\": the code must be a decimal integer");
  refused_after([](auto& j) { j["fault_codes"]["9"] = 9; }, "fault_codes.\"9\" must be a non-empty string");
  refused_after([](auto& j) { j["fault_codes"]["9"] = ""; }, "fault_codes.\"9\" must be a non-empty string");
  refused_after([](auto& j) { j["signals"]["fault_reset"] = {{"table", "holding_register"}, {"address", 9}}; }, "signals.fault_reset must be a coil");
  refused_after([](auto& j) { j["signals"]["host_heartbeat"]["type"] = "float32"; },
                "signals.host_heartbeat must be a holding_register of type uint16 or uint32");
  refused_after([](auto& j) { j["signals"]["host_heartbeat"]["table"] = "input_register"; }, "signals.host_heartbeat is a command");
  refused_after([](auto& j) { j["signals"]["fault_reset"]["address"] = 2; }, "signals.fault_reset overlaps signals.estop at coil 2");
}

TEST_CASE("sample windows: the shipped map's window, and records that encode and decode back") {
  const RegisterMap m = RegisterMap::from_json(slurp(HYSTLAB_MAPS + "/default_load_frame.json"));
  REQUIRE(m.sample_window());
  const SampleWindow& w = *m.sample_window();
  CHECK(w.record_width == 10);  // counter, displacement, force, command (2 each), status, fault
  CHECK(w.records_per_read() == 12);
  CHECK(w.period_s == doctest::Approx(0.001));
  const RegisterMap shaker = RegisterMap::from_json(slurp(HYSTLAB_MAPS + "/default_shaker.json"));
  REQUIRE(shaker.sample_window());
  CHECK(shaker.sample_window()->record_width == 12);  // counter, 2 displacements, 2 accelerations (2 each), status, fault
  CHECK(shaker.sample_window()->records_per_read() == 10);
  CHECK(shaker.sample_window()->records == 500);  // half a second of a host's absence at 1 kHz
  CHECK(shaker.sample_period_s() == doctest::Approx(0.001));
  SignalArray in{}, out{};
  out.fill(-7);
  in[static_cast<std::size_t>(Signal::sample_counter)] = 4000000123.0;
  in[static_cast<std::size_t>(Signal::displacement_mm)] = -1.25;
  in[static_cast<std::size_t>(Signal::force_N)] = 312.5;
  in[static_cast<std::size_t>(Signal::command_mm)] = 0.5;
  in[static_cast<std::size_t>(Signal::status_word)] = 0x43;
  in[static_cast<std::size_t>(Signal::fault_code)] = 2;
  std::uint16_t words[10] = {};
  REQUIRE_FALSE(encode_record(m, w, in, words));
  CHECK(words[0] == 0xEE6B);  // the counter, big-endian words: 4000000123 = 0xEE6B287B
  CHECK(words[1] == 0x287B);
  REQUIRE_FALSE(decode_record(m, w, words, out));
  for (const Signal s : w.fields) CHECK(out[static_cast<std::size_t>(s)] == in[static_cast<std::size_t>(s)]);
  CHECK(out[static_cast<std::size_t>(Signal::heartbeat)] == -7);  // not a field: untouched
  CHECK(encode_record(m, w, in, std::span<std::uint16_t>(words, 9)) == ProtocolError::wrong_length);
  in[static_cast<std::size_t>(Signal::force_N)] = std::nan("");
  CHECK(encode_record(m, w, in, words) == ProtocolError::not_finite);
  words[4] = 0x7F7F;  // force far beyond the map's max of 5000 N
  CHECK(decode_record(m, w, words, out) == ProtocolError::out_of_range);
}

TEST_CASE("the controller's sample clock: sample_period_s, or the window's period; a bad one is named") {
  CHECK(RegisterMap::from_json(slurp(HYSTLAB_MAPS + "/default_shaker.json")).sample_period_s() == doctest::Approx(0.001));
  CHECK(RegisterMap::from_json(slurp(HYSTLAB_MAPS + "/default_load_frame.json")).sample_period_s() == doctest::Approx(0.001));
  CHECK(RegisterMap::from_json(slurp(HYSTLAB_MAPS + "/vendor_b_load_frame.json")).sample_period_s() == 0.0);  // it does not say
  refused_after([](auto& j) { j["sample_period_s"] = 0; }, "sample_period_s must be a number of seconds > 0 and <= 1");
  refused_after([](auto& j) { j["sample_period_s"] = "1 ms"; }, "sample_period_s must be a number of seconds > 0 and <= 1");
  refused_after([](auto& j) { j["sample_period_s"] = 0.002; }, "sample_period_s differs from sample_window.period_s");
}

TEST_CASE("sample windows: a bad window is rejected with the field named") {
  refused_after([](auto& j) { j["sample_window"] = 3; }, "sample_window must be an object");
  refused_after([](auto& j) { j["sample_window"]["depth"] = 3; }, "sample_window has an unknown field 'depth'");
  refused_after([](auto& j) { j["sample_window"]["table"] = "coil"; }, "sample_window.table");
  refused_after([](auto& j) { j["sample_window"].erase("address"); }, "sample_window.address is missing");
  refused_after([](auto& j) { j["sample_window"]["address"] = 70000; }, "sample_window.address must be an integer from 0 to 65535");
  refused_after([](auto& j) { j["sample_window"]["records"] = 0; }, "sample_window.records must be an integer from 1 to 10000");
  refused_after([](auto& j) { j["sample_window"]["period_s"] = -1; }, "sample_window.period_s must be > 0");
  refused_after([](auto& j) { j["sample_window"].erase("period_s"); }, "sample_window.period_s is missing");
  refused_after([](auto& j) { j["sample_window"]["fields"] = nlohmann::json::array(); }, "sample_window.fields must be a non-empty array");
  refused_after([](auto& j) { j["sample_window"]["fields"].push_back("torque"); }, "sample_window.fields has \"torque\", which is not a signal");
  refused_after([](auto& j) { j["sample_window"]["fields"].push_back("setpoint_mm"); }, "which is not a register measurement");
  refused_after([](auto& j) { j["sample_window"]["fields"].push_back("force_N"); }, "sample_window.fields has 'force_N' twice");
  refused_after([](auto& j) { j["sample_window"]["fields"] = {"displacement_mm", "force_N"}; }, "sample_window.fields must hold sample_counter");
  refused_after([](auto& j) { j["sample_window"]["address"] = 0; }, "sample_window overlaps signals.command_mm at input_register 4");
  refused_after([](auto& j) { j["sample_window"]["address"] = 65000; }, "sample_window runs past address 65535");
  refused_after([](auto& j) { j["signals"].erase("command_mm"); }, "'command_mm', which 'signals' does not define");
}

TEST_CASE("CAN: every frame encodes byte for byte and decodes back") {
  can_frame f{};
  REQUIRE_FALSE(can::encode(can::Command{1.5, 2.5, true, false, true, 2}, 5, f));
  CHECK(f.can_id == 0x205);
  CHECK(f.can_dlc == 8);
  const std::uint8_t cmd[8] = {0xDC, 0x05, 0, 0, 0xFA, 0x00, 0x05, 0x02};  // 1500 µm, 250 (0.01 mm/s), flags 101b, mode 2
  CHECK(std::memcmp(f.data, cmd, 8) == 0);
  can::Message m;
  REQUIRE_FALSE(can::decode(f, 5, m));
  CHECK(std::get<can::Command>(m).setpoint_mm == doctest::Approx(1.5));
  CHECK(std::get<can::Command>(m).estop);

  REQUIRE_FALSE(can::encode(can::StatusA{-0.002, 157.5}, 1, f));
  const std::uint8_t sa[8] = {0xFE, 0xFF, 0xFF, 0xFF, 0x3C, 0x67, 0x02, 0x00};  // -2 µm, 157500 mN
  CHECK(f.can_id == 0x181);
  CHECK(std::memcmp(f.data, sa, 8) == 0);
  REQUIRE_FALSE(can::decode(f, 1, m));
  CHECK(std::get<can::StatusA>(m).force_N == doctest::Approx(157.5));

  REQUIRE_FALSE(can::encode(can::StatusC{0x01020304}, 1, f));
  CHECK(f.can_dlc == 4);
  CHECK(f.data[0] == 0x04);
  CHECK(f.data[3] == 0x01);
  REQUIRE_FALSE(can::encode(can::ShakerStatus{-1.0, 2.0, 0.5, -0.5}, 3, f));
  REQUIRE_FALSE(can::decode(f, 3, m));
  CHECK(std::get<can::ShakerStatus>(m).mass_displacement_mm == doctest::Approx(-0.5));
}

TEST_CASE("CAN: malformed frames are typed decode errors") {
  can_frame f{};
  REQUIRE_FALSE(can::encode(can::StatusA{1, 2}, 1, f));
  can::Message m;
  can_frame g = f;
  g.can_dlc = 7;
  CHECK(can::decode(g, 1, m) == ProtocolError::wrong_length);
  g = f;
  g.can_id = 0x123;
  CHECK(can::decode(g, 1, m) == ProtocolError::unknown_id);
  CHECK(can::decode(f, 2, m) == ProtocolError::unknown_id);  // another node's frame
  g = f;
  g.can_id = 0x00EA1181;  // stray bits above the 11-bit identifier (found by the fuzzer)
  CHECK(can::decode(g, 1, m) == ProtocolError::unknown_id);
  g = f;
  g.can_id |= CAN_RTR_FLAG;
  CHECK(can::decode(g, 1, m) == ProtocolError::unknown_id);
  REQUIRE_FALSE(can::encode(can::Command{}, 1, f));
  f.data[6] = 0x80;
  CHECK(can::decode(f, 1, m) == ProtocolError::reserved_bits);
  f.data[6] = 0;
  f.data[7] = 9;
  CHECK(can::decode(f, 1, m) == ProtocolError::out_of_range);
  CHECK(can::encode(can::Command{0, 1000.0}, 1, f) == ProtocolError::out_of_range);  // ramp > 655.35
  CHECK(can::encode(can::StatusA{}, 0, f) == ProtocolError::out_of_range);
}

TEST_CASE("Modbus CRC-16 matches the standard's example") {
  const std::uint8_t frame[] = {0x01, 0x03, 0x00, 0x00, 0x00, 0x0A};  // read 10 holding registers from slave 1
  CHECK(crc16_modbus(frame) == 0xCDC5);                               // sent as C5 CD
}
