// A Modbus client no one here wrote, Debian's mbpoll, reads hystlab-sim's documented values.
#include <doctest/doctest.h>

#include <cstdio>
#include <map>
#include <string>

#include "../support/build_paths.hpp"
#include "hystlab/drivers/modbus_rig.hpp"
#include "hystlab/protocols/default_maps.hpp"
#include "sim_process.hpp"

namespace {
// Runs mbpoll once and returns register -> value.
std::map<int, long> mbpoll(int port, int slave, int table, int start, int count) {
  const std::string cmd = "mbpoll -m tcp -0 -1 -q -p " + std::to_string(port) + " -a " + std::to_string(slave) + " -t " + std::to_string(table) + " -r " +
                          std::to_string(start) + " -c " + std::to_string(count) + " 127.0.0.1 2>&1";
  std::map<int, long> out;
  FILE* p = popen(cmd.c_str(), "r");
  REQUIRE(p != nullptr);
  char line[256];
  while (fgets(line, sizeof line, p)) {
    int reg = 0;
    long v = 0;
    if (std::sscanf(line, "[%d]: %ld", &reg, &v) == 2) out[reg] = v;
  }
  pclose(p);
  return out;
}
}  // namespace

TEST_CASE("mbpoll reads the default map's documented values at rest, and a setpoint the driver wrote") {
  hystlab::test::SimProcess sim({"--port", "0", "--noise", "0"});
  auto in = mbpoll(sim.modbus_port, 1, 3, 0, 12);
  REQUIRE(in.size() == 12);
  CHECK(in[0] == 0);  // displacement float32 0.0
  CHECK(in[2] == 0);  // force 0.0
  CHECK(in[6] == 1);  // status: ready
  CHECK(in[7] == 0);  // no fault
  hystlab::drivers::ModbusRigConfig c;
  c.port = sim.modbus_port;
  c.map = hystlab::protocols::RegisterMap::from_json(hystlab::protocols::kDefaultLoadFrameMap);
  hystlab::drivers::ModbusRig rig(c);
  REQUIRE_FALSE(rig.connect(hystlab::test::steady_now()));
  REQUIRE_FALSE(rig.command(1.5, 2.5));
  auto hold = mbpoll(sim.modbus_port, 1, 4, 0, 4);
  CHECK(hold[0] == 0x3FC0);  // 1.5f, big-endian words
  CHECK(hold[1] == 0x0000);
  CHECK(hold[2] == 0x4020);  // 2.5f
}

TEST_CASE("mbpoll reads the vendor B map: other addresses, swapped words, scaled integers") {
  hystlab::test::SimProcess sim({"--port", "0", "--noise", "0", "--map", HYSTLAB_MAPS + "/vendor_b_load_frame.json"});
  auto in = mbpoll(sim.modbus_port, 17, 3, 3000, 10);
  REQUIRE(in.size() == 10);
  CHECK(in[3000] == 1);  // status: ready
  CHECK(in[3002] == 0);
  hystlab::drivers::ModbusRigConfig c;
  c.port = sim.modbus_port;
  std::FILE* f = std::fopen((HYSTLAB_MAPS + "/vendor_b_load_frame.json").c_str(), "r");
  REQUIRE(f);
  std::string text;
  for (int ch; (ch = std::fgetc(f)) != EOF;) text += static_cast<char>(ch);
  std::fclose(f);
  c.map = hystlab::protocols::RegisterMap::from_json(text);
  hystlab::drivers::ModbusRig rig(c);
  REQUIRE_FALSE(rig.connect(hystlab::test::steady_now()));
  REQUIRE_FALSE(rig.command(-1.5, 2.5));
  auto hold = mbpoll(sim.modbus_port, 17, 4, 4100, 3);
  CHECK(hold[4100] == 0xFA24);  // -1500 µm as int32: low word 0xFA24 first (swapped)
  CHECK(hold[4101] == 0xFFFF);
  CHECK(hold[4102] == 250);  // 2.5 mm/s in 0.01 mm/s
}
