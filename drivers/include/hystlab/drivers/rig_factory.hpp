#pragma once
// Rigs from configuration: the only difference between a real rig and a simulated one.
//   {"name": "frame A", "transport": "modbus-tcp", "host": "127.0.0.1", "port": 1502, "map": "default"}
//   {"transport": "modbus-rtu", "device": "/dev/ttyUSB0", "baud": 115200, "parity": "E", "map": "maps/b.json"}
//   {"transport": "can", "can_interface": "can0", "can_node": 1}   (or "can_fd": 3 for an inherited fd)
// Fields and defaults: drivers/RIGS.md. Errors name the field (RigConfigError), at start-up.
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "hystlab/drivers/rig.hpp"

namespace hystlab::drivers {

struct RigConfigError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// where: the config path of this object for messages ("rigs[0]"); base: where relative map
// paths start. Opening a CAN interface on a kernel without SocketCAN throws std::system_error.
[[nodiscard]] std::unique_ptr<Rig> make_rig(const nlohmann::json& config, const std::string& where = "rig", const std::filesystem::path& base = ".");

}  // namespace hystlab::drivers
