// hystlab-sim: a simulated load frame or shaker that speaks the real protocols over real sockets.
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "can_endpoint.hpp"
#include "control_channel.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/linear_spring.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "hystlab/protocols/default_maps.hpp"
#include "modbus_endpoint.hpp"
#include "shakedown_specimen.hpp"
#include "world_clock.hpp"

namespace {
using namespace hystlab;

const char* kHelp = R"(usage: hystlab-sim [options]

A simulated rig that speaks hystlab's real protocols over real sockets.
  --rig load_frame|shaker        which rig (default load_frame)
  --transport tcp|rtu|can        Modbus TCP (default), Modbus RTU on a new pty, or CAN on --can-fd
  --address A  --port P          TCP address and port (default 127.0.0.1:1502; port 0: any free port)
  --map M.json                   register map (default: the shipped map for the rig)
  --can-fd N  --can-node N  --can-rate HZ   CAN: inherited fd carrying struct can_frame, node id, status rate
  --time-scale S                 simulated seconds per wall-clock second (default 1)
  --pace auto|on|off             the world runs at most a few request intervals past the host's last request
                                 (CAN: the last time it had read every frame), then waits for the next
                                 (auto: on when --time-scale > 1; see SIM.md)
  --sample-rate HZ               simulated samples per simulated second (default 1000)
  --seed N  --noise N  --drift N_PER_S      load cell noise (1 sigma, N) and drift
  --params P.json | --table T.json          the specimen (default: Table 1, corners smoothed)
  --linear K                     a linear spring of K N/mm instead (the reference a hysteretic isolator is compared with)
  --corner-width MM              corner smoothing width of the specimen (default 0.05; 0: none)
  --shakedown EXTRA,TAU          an untrained specimen (simplified model only): its upper plateau starts EXTRA N
                                 higher and settles by exp(-N/TAU) over transformation cycles N (see SIM.md)
  --fault SPEC                   start with a fault: drop, delay=MS, stall=MS, exception=CODE, crc, freeze, overload,
                                 can-silent, or a controller event: estop, latch=CODE, deadband=MM, overtravel=MM
  --deadband-mm D                load frame servo dead band: no correction while |command - displacement| < D (default 0)
  --mode N                       the controller moves only while the map's mode register (CAN: the command's mode)
                                 holds N (default 1; a map without mode has no interlock). It starts at 0
  --host-timeout-ms T            stop with fault 4 when the host's host_heartbeat has not changed for T wall-clock ms
                                 of the world's time (a paced world waiting for its host does not count)
                                 while the drive is on (default 0: off; a real controller would have it on)
  --control-port P               text control channel on 127.0.0.1 (default 0: any free port)
  --duration S                   stop after S wall-clock seconds (default: run until SIGTERM or 'quit')
  --exit-with-parent 1           stop when the process that started it is gone (a supervising daemon)
  --realtime N                   run at SCHED_FIFO priority N when allowed: it stands in for a
                                 controller with a CPU of its own (it only ever blocks in poll)
On start it prints one line per endpoint ("modbus-tcp 127.0.0.1:1502", "control 127.0.0.1:40123") and "ready".
)";

volatile sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

struct Args {
  std::string rig = "load_frame", transport = "tcp", address = "127.0.0.1", map, params, table, pace = "auto";
  int port = 1502, can_fd = -1, can_node = 1, control_port = 0, realtime = 0;
  double time_scale = 1, sample_rate = 1000, can_rate = 1000, noise = 0.05, drift = 0, corner = 0.05, duration = 0;
  double deadband_mm = 0, host_timeout_ms = 0, mode = 1;
  double shakedown_N = 0, shakedown_tau = 0;  // 0: a trained specimen
  double linear = 0;                          // > 0: a linear spring of this stiffness (N/mm)
  bool exit_with_parent = false;
  std::uint64_t seed = 1;
  std::vector<std::string> faults;
};

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open '" + path + "'");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

Args parse(int argc, char** argv) {
  Args a;
  for (int k = 1; k < argc; ++k) {
    const std::string o = argv[k];
    if (o == "--help" || o == "-h") {
      std::cout << kHelp;
      std::exit(0);
    }
    if (k + 1 >= argc) throw std::runtime_error("option " + o + " needs a value (see --help)");
    const std::string v = argv[++k];
    auto num = [&] {
      try {
        std::size_t used = 0;
        const double d = std::stod(v, &used);
        if (used != v.size()) throw std::invalid_argument(v);
        return d;
      } catch (...) {
        throw std::runtime_error("option " + o + ": '" + v + "' is not a number");
      }
    };
    if (o == "--rig")
      a.rig = v;
    else if (o == "--transport")
      a.transport = v;
    else if (o == "--address")
      a.address = v;
    else if (o == "--port")
      a.port = static_cast<int>(num());
    else if (o == "--map")
      a.map = v;
    else if (o == "--can-fd")
      a.can_fd = static_cast<int>(num());
    else if (o == "--can-node")
      a.can_node = static_cast<int>(num());
    else if (o == "--can-rate")
      a.can_rate = num();
    else if (o == "--time-scale")
      a.time_scale = num();
    else if (o == "--pace")
      a.pace = v;
    else if (o == "--sample-rate")
      a.sample_rate = num();
    else if (o == "--seed")
      a.seed = static_cast<std::uint64_t>(num());
    else if (o == "--noise")
      a.noise = num();
    else if (o == "--drift")
      a.drift = num();
    else if (o == "--params")
      a.params = v;
    else if (o == "--table")
      a.table = v;
    else if (o == "--linear")
      a.linear = num();
    else if (o == "--corner-width")
      a.corner = num();
    else if (o == "--shakedown") {
      const auto comma = v.find(',');
      char* end = nullptr;
      a.shakedown_N = std::strtod(v.c_str(), &end);
      const bool first_ok = comma != std::string::npos && end == v.c_str() + comma;
      a.shakedown_tau = first_ok ? std::strtod(v.c_str() + comma + 1, &end) : 0.0;
      if (!first_ok || end != v.c_str() + v.size() || !(a.shakedown_N > 0) || !(a.shakedown_tau > 0) || !std::isfinite(a.shakedown_N) ||
          !std::isfinite(a.shakedown_tau))
        throw std::runtime_error("option --shakedown: expected EXTRA_N,TAU_CYCLES, both > 0 (e.g. 10,3), got '" + v + "'");
    } else if (o == "--fault")
      a.faults.push_back(v);
    else if (o == "--deadband-mm")
      a.deadband_mm = num();
    else if (o == "--mode")
      a.mode = num();
    else if (o == "--host-timeout-ms")
      a.host_timeout_ms = num();
    else if (o == "--control-port")
      a.control_port = static_cast<int>(num());
    else if (o == "--duration")
      a.duration = num();
    else if (o == "--exit-with-parent")
      a.exit_with_parent = num() != 0;
    else if (o == "--realtime")
      a.realtime = static_cast<int>(num());
    else
      throw std::runtime_error("unknown option " + o + " (see --help)");
  }
  if (a.rig != "load_frame" && a.rig != "shaker") throw std::runtime_error("--rig must be load_frame or shaker");
  if (a.transport != "tcp" && a.transport != "rtu" && a.transport != "can") throw std::runtime_error("--transport must be tcp, rtu or can");
  if (a.pace != "auto" && a.pace != "on" && a.pace != "off") throw std::runtime_error("--pace must be auto, on or off");
  if (a.transport == "can" && a.can_fd < 0) throw std::runtime_error("--transport can needs --can-fd");
  if (!(a.time_scale > 0) || !(a.sample_rate > 0) || !(a.can_rate > 0)) throw std::runtime_error("rates and time scale must be > 0");
  if (!(a.deadband_mm >= 0) || !std::isfinite(a.deadband_mm)) throw std::runtime_error("--deadband-mm must be a number >= 0");
  if (!(a.host_timeout_ms >= 0) || !std::isfinite(a.host_timeout_ms)) throw std::runtime_error("--host-timeout-ms must be a number >= 0");
  if (a.mode < 0 || a.mode > 65535 || a.mode != std::floor(a.mode)) throw std::runtime_error("--mode must be a whole number from 0 to 65535");
  if (a.linear != 0 && (!(a.linear > 0) || a.linear > 1e6 || !a.params.empty() || !a.table.empty() || a.shakedown_N > 0))
    throw std::runtime_error("--linear K: a stiffness above 0 and at most 1e6 N/mm, without --params, --table or --shakedown");
  return a;
}

std::unique_ptr<models::HysteresisModel> specimen(const Args& a) {
  if (a.linear > 0) return std::make_unique<models::LinearSpring>(a.linear);
  if (!a.table.empty()) {
    if (a.shakedown_N > 0) throw std::runtime_error("option --shakedown needs the simplified model (not --table)");
    return std::make_unique<models::PreisachModel>(models::table_from_json(read_file(a.table)).table);
  }
  const models::SmaParameters p = a.params.empty() ? models::table1_parameters() : models::params_from_json(read_file(a.params));
  if (a.shakedown_N > 0) return std::make_unique<sim::ShakedownSpecimen>(p, a.shakedown_N, a.shakedown_tau);
  return std::make_unique<models::SimplifiedSmaModel>(p);
}

// The Modbus map (none on CAN), checked against the rig and the sample rate.
std::optional<protocols::RegisterMap> load_map(const Args& a) {
  if (a.transport == "can") return std::nullopt;
  const std::string text = a.map.empty() ? (a.rig == "shaker" ? protocols::kDefaultShakerMap : protocols::kDefaultLoadFrameMap) : read_file(a.map);
  protocols::RegisterMap map = protocols::RegisterMap::from_json(text);
  if ((map.kind() == protocols::RigKind::shaker) != (a.rig == "shaker")) throw std::runtime_error("the map is for another kind of rig than --rig " + a.rig);
  if (const double p = map.sample_period_s(); p > 0 && std::fabs(p * a.sample_rate - 1.0) > 1e-9)
    throw std::runtime_error(std::string(map.sample_window() ? "the map's sample_window.period_s (" : "the map's sample_period_s (") + std::to_string(p) +
                             " s) is not the period of --sample-rate " + std::to_string(a.sample_rate) + " Hz");
  return map;
}

// The interlocks exist where the protocol carries their signals: CAN's load frame command has a
// mode (its shaker command has none).
sim::ControllerParams controller_params(const Args& a, const std::optional<protocols::RegisterMap>& map) {
  sim::ControllerParams c;
  c.mode = static_cast<std::uint16_t>(a.mode);
  c.mode_interlock = map ? map->find(protocols::Signal::mode) != nullptr : a.rig == "load_frame";
  // The host's link runs on wall-clock time whatever the time scale: the controller counts it in
  // its own (simulated) seconds, so the wall-clock timeout is scaled into them.
  c.host_timeout_s = map && map->find(protocols::Signal::host_heartbeat) ? a.host_timeout_ms * 1e-3 * a.time_scale : 0.0;
  return c;
}

sim::SimRig make_rig(const Args& a, const sim::ControllerParams& controller) {
  if (a.rig == "shaker") {
    sim::ShakerParams p;
    p.controller = controller;
    return sim::SimRig(std::make_unique<sim::ShakerSim>(*specimen(a), p));
  }
  sim::LoadFrameParams p;
  p.noise_N = a.noise;
  p.drift_N_per_s = a.drift;
  p.corner_width_mm = a.corner;
  p.deadband_mm = a.deadband_mm;
  p.seed = a.seed;
  p.controller = controller;
  return sim::SimRig(std::make_unique<sim::LoadFrameSim>(specimen(a), p));
}

int run(const Args& a) {
  std::optional<protocols::RegisterMap> map = load_map(a);
  sim::SimRig rig = make_rig(a, controller_params(a, map));
  sim::Faults faults;
  for (const auto& f : a.faults)
    if (const std::string err = sim::apply_fault(f, faults, rig); !err.empty()) throw std::runtime_error(err);
  std::optional<sim::ModbusEndpoint> modbus;
  std::optional<sim::CanEndpoint> can;
  if (a.transport == "can") {
    can.emplace(a.can_fd, a.can_node, a.can_rate);
  } else {
    modbus.emplace(a.transport == "tcp" ? sim::ModbusEndpoint::Transport::tcp : sim::ModbusEndpoint::Transport::rtu, a.address, a.port, std::move(*map));
    std::cout << modbus->where() << "\n";
  }
  if (a.realtime > 0) {
    sched_param sp{};
    sp.sched_priority = a.realtime;
    if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
      std::cerr << "hystlab-sim: staying at normal priority (SCHED_FIFO " << a.realtime << " refused: " << std::strerror(errno) << ")\n";
  }
  sim::ControlChannel control(a.control_port);
  std::cout << "control 127.0.0.1:" << control.port() << "\nready" << std::endl;

  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  auto wall = [&] { return std::chrono::duration<double>(clock::now() - t0).count(); };
  const double sample_dt = 1.0 / a.sample_rate;
  sim::WorldClock world(a.time_scale, sample_dt, a.pace == "on" || (a.pace == "auto" && a.time_scale > 1));
  bool was_dropping = false;
  std::vector<int> fds;
  std::vector<pollfd> pfds;
  // Brings the physics up to now (world_clock.hpp) and publishes it: before every wait, and
  // again right before answering, so an answer never carries values older than the request.
  auto advance = [&](double now) {
    for (long n = world.steps_due(now); n > 0; --n) {
      rig.step(sample_dt);
      if (modbus && !faults.freeze) modbus->record(rig.measurements(faults));  // the controller's own clock
    }
    const sim::SignalValues m = rig.measurements(faults);
    if (modbus && !faults.freeze) modbus->publish(m);
    return m;
  };
  // CAN sends cyclic frames, so it wakes every millisecond; Modbus only answers, so it sleeps
  // until a request comes (or 15 ms pass: within the catch-up limit above).
  const int wait_ms = can ? 1 : 15;
  const pid_t parent = getppid();
  while (!g_stop && (a.duration <= 0 || wall() < a.duration)) {
    if (a.exit_with_parent && getppid() != parent) break;  // the supervisor died (even by kill -9)
    const double now = wall();
    if (can && can->host_caught_up()) world.host_request(now);  // it read all we sent: a sign of life
    const sim::SignalValues m = advance(now);
    if (faults.drop && !was_dropping && modbus) modbus->drop_clients();
    was_dropping = faults.drop;
    if (can) can->maybe_send(now, m, rig.kind(), faults.freeze ? sim::Faults{.can_silent = true} : faults);
    fds.clear();
    if (modbus) modbus->fds(fds);
    if (can) fds.push_back(can->fd());
    control.fds(fds);
    pfds.clear();
    for (int fd : fds) pfds.push_back(pollfd{fd, POLLIN, 0});
    if (poll(pfds.data(), pfds.size(), wait_ms) <= 0) continue;
    if (modbus && faults.stall_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(faults.stall_ms));
    if (modbus) {
      const double arrived = wall();
      const bool asked = std::any_of(pfds.begin(), pfds.end(), [&](const pollfd& p) { return (p.revents & POLLIN) && !control.owns(p.fd); });
      if (asked) world.host_request(arrived);  // a host's request (a test's status query is none)
      advance(arrived);
    }
    for (const pollfd& p : pfds) {
      if (!(p.revents & (POLLIN | POLLHUP | POLLERR))) continue;
      if (control.owns(p.fd)) {
        std::ostringstream status;
        status << "t=" << rig.time_s() << " lost=" << world.lost_s();
        if (control.handle(p.fd, faults, rig, status.str())) g_stop = 1;
      } else if (can && p.fd == can->fd()) {
        can->receive(rig);
      } else if (modbus) {
        modbus->handle(p.fd, faults, rig);
      }
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  signal(SIGTERM, on_signal);
  signal(SIGINT, on_signal);
  signal(SIGPIPE, SIG_IGN);
  try {
    return run(parse(argc, argv));
  } catch (const std::exception& e) {
    std::cerr << "hystlab-sim: error: " << e.what() << "\n";
    return 2;
  }
}
