#include "hystlab/drivers/rig_factory.hpp"

#include <fstream>
#include <set>
#include <sstream>

#include "hystlab/drivers/can_rig.hpp"
#include "hystlab/drivers/modbus_rig.hpp"
#include "hystlab/protocols/default_maps.hpp"

namespace hystlab::drivers {
namespace {
using nlohmann::json;

class Reader {
 public:
  Reader(const json& j, std::string where) : j_(j), where_(std::move(where)) {
    if (!j_.is_object()) fail("", "must be an object");
  }
  [[noreturn]] void fail(const std::string& field, const std::string& why) const {
    throw RigConfigError(where_ + (field.empty() ? "" : "." + field) + " " + why);
  }
  std::string text(const std::string& f, const std::string& def) const {
    if (!j_.contains(f)) return def;
    if (!j_[f].is_string()) fail(f, "must be a string");
    return j_[f].get<std::string>();
  }
  long integer(const std::string& f, long def, long lo, long hi) const {
    if (!j_.contains(f)) return def;
    if (!j_[f].is_number_integer() || j_[f].get<long>() < lo || j_[f].get<long>() > hi)
      fail(f, "must be an integer from " + std::to_string(lo) + " to " + std::to_string(hi));
    return j_[f].get<long>();
  }
  void only(const std::set<std::string>& known) const {
    for (const auto& [k, _] : j_.items())
      if (!known.count(k)) fail(k, "is not a known field");
  }
  const json& at(const std::string& f) const { return j_[f]; }
  bool has(const std::string& f) const { return j_.contains(f); }

 private:
  const json& j_;
  std::string where_;
};

protocols::RegisterMap load_map(const Reader& r, protocols::RigKind kind, const std::filesystem::path& base) {
  std::string text;
  if (!r.has("map") || (r.at("map").is_string() && r.at("map") == "default")) {
    text = kind == protocols::RigKind::shaker ? protocols::kDefaultShakerMap : protocols::kDefaultLoadFrameMap;
  } else if (r.at("map").is_object()) {
    text = r.at("map").dump();
  } else if (r.at("map").is_string()) {
    const std::filesystem::path p = base / r.at("map").get<std::string>();
    std::ifstream in(p);
    if (!in) r.fail("map", "names a file that cannot be opened: " + p.string());
    std::stringstream s;
    s << in.rdbuf();
    text = s.str();
  } else {
    r.fail("map", "must be \"default\", a file name, or a map object");
  }
  try {
    auto map = protocols::RegisterMap::from_json(text);
    if (map.kind() != kind) r.fail("map", "is for another kind of rig than 'rig'");
    return map;
  } catch (const protocols::MapError& e) {
    r.fail("map", std::string("is not usable: ") + e.what());
  }
}
}  // namespace

std::unique_ptr<Rig> make_rig(const json& config, const std::string& where, const std::filesystem::path& base) {
  const Reader r(config, where);
  r.only({"name",
          "transport",
          "rig",
          "host",
          "port",
          "device",
          "baud",
          "parity",
          "data_bits",
          "stop_bits",
          "map",
          "slave",
          "response_timeout_ms",
          "byte_timeout_ms",
          "reconnect_min_ms",
          "reconnect_max_ms",
          "stale_after_ms",
          "can_interface",
          "can_fd",
          "can_node",
          "status_timeout_ms",
          "block_reads"});
  const std::string transport = r.text("transport", "");
  const std::string name = r.text("name", "rig");
  const std::string rig = r.text("rig", "load_frame");
  if (rig != "load_frame" && rig != "shaker") r.fail("rig", "must be \"load_frame\" or \"shaker\"");
  const auto kind = rig == "shaker" ? protocols::RigKind::shaker : protocols::RigKind::load_frame;
  if (transport == "modbus-tcp" || transport == "modbus-rtu") {
    ModbusRigConfig c;
    c.name = name;
    c.transport = transport == "modbus-tcp" ? ModbusRigConfig::Transport::tcp : ModbusRigConfig::Transport::rtu;
    c.host = r.text("host", c.host);
    c.port = static_cast<int>(r.integer("port", 502, 1, 65535));
    c.device = r.text("device", "");
    if (c.transport == ModbusRigConfig::Transport::rtu && c.device.empty()) r.fail("device", "is required for modbus-rtu");
    c.baud = static_cast<int>(r.integer("baud", c.baud, 300, 4'000'000));
    const std::string parity = r.text("parity", "N");
    if (parity != "N" && parity != "E" && parity != "O") r.fail("parity", "must be \"N\", \"E\" or \"O\"");
    c.parity = parity[0];
    c.data_bits = static_cast<int>(r.integer("data_bits", 8, 5, 8));
    c.stop_bits = static_cast<int>(r.integer("stop_bits", 1, 1, 2));
    c.slave = static_cast<int>(r.integer("slave", 0, 0, 247));
    c.response_timeout_s = static_cast<double>(r.integer("response_timeout_ms", 50, 1, 60000)) / 1e3;
    c.byte_timeout_s = static_cast<double>(r.integer("byte_timeout_ms", 10, 1, 60000)) / 1e3;
    c.reconnect_min_s = static_cast<double>(r.integer("reconnect_min_ms", 50, 1, 600000)) / 1e3;
    c.reconnect_max_s = static_cast<double>(r.integer("reconnect_max_ms", 2000, 1, 600000)) / 1e3;
    c.stale_after_s = static_cast<double>(r.integer("stale_after_ms", 500, 1, 600000)) / 1e3;
    c.map = load_map(r, kind, base);
    if (r.has("block_reads")) {
      if (!r.at("block_reads").is_boolean()) r.fail("block_reads", "must be true or false");
      c.block_reads = r.at("block_reads").get<bool>();
    }
    try {
      return std::make_unique<ModbusRig>(std::move(c));
    } catch (const std::invalid_argument& e) {
      r.fail("block_reads", std::string("cannot be used: ") + e.what());
    }
  }
  if (transport == "can") {
    CanRigConfig c;
    c.name = name;
    c.node = static_cast<int>(r.integer("can_node", 1, 1, 127));
    c.status_timeout_ms = static_cast<int>(r.integer("status_timeout_ms", 100, 1, 60000));
    c.stale_after_s = static_cast<double>(r.integer("stale_after_ms", 500, 1, 600000)) / 1e3;
    if (r.has("can_fd") == r.has("can_interface")) r.fail("can_interface", "or can_fd: exactly one is required for can");
    if (r.has("can_fd")) return std::make_unique<CanRig>(std::make_unique<FdCanChannel>(static_cast<int>(r.integer("can_fd", -1, 0, 65535)), "fd"), c);
    return std::make_unique<CanRig>(open_socketcan(r.text("can_interface", "")), c);
  }
  r.fail("transport", "must be \"modbus-tcp\", \"modbus-rtu\" or \"can\" (got \"" + transport + "\")");
}

}  // namespace hystlab::drivers
