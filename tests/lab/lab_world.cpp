// A small lab for the lab view's browser test (tests/browser/lab_test.mjs): its own PostgreSQL and
// MQTT broker, two daemons with simulated load frames running a campaign each (replicating,
// publishing), and the lab view over them. Prints "lab view: URL" once the campaigns' samples are
// in the lab database, then takes commands on stdin, one a line: "kill frame-pc-2" (SIGKILL, as a
// crash), "quit" (or end of input) stops everything.
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "../support/mosquitto_broker.hpp"
#include "lab_daemon.hpp"

using namespace hystlab;

int main() {
  try {
    test_support::PostgresServer pg;
    test_support::MosquittoBroker broker;
    setenv("HYSTLAB_TEST_PG_PASSWORD", test_support::PostgresServer::kPassword, 1);
    std::vector<std::unique_ptr<lab_test::LabDaemon>> daemons;
    for (const char* name : {"frame-pc-1", "frame-pc-2"})
      // 10 times real time: each campaign runs about 30 s, long enough to be seen running.
      daemons.push_back(std::make_unique<lab_test::LabDaemon>(pg, lab_test::LabDaemonOptions{.name = name, .mqtt_port = broker.port(), .time_scale = 10}));
    int k = 0;
    for (const auto& d : daemons) {
      nlohmann::json plan = nlohmann::json::parse(lab_test::kFotPlan);
      plan["specimen"] = k++ == 0 ? "SMA spring 7" : "SMA spring 8";
      d->submit(plan.dump());
    }
    for (const auto& d : daemons)
      if (!test_support::wait_until([&] { return d->get("/api/status")["lab"]["postgresql"]["samples"].get<std::int64_t>() > 2000; }, 120))
        throw std::runtime_error(d->name() + " replicated nothing in 120 s: " + d->text("/api/status"));
    lab_test::LabDaemon view(pg, {.name = "", .mqtt_port = broker.port(), .view = true});
    std::printf("lab view: http://127.0.0.1:%d/\n", view.port());
    std::fflush(stdout);
    std::string line;
    while (std::getline(std::cin, line) && line != "quit") {
      for (const auto& d : daemons)
        if (line == "kill " + d->name()) d->stop(SIGKILL);
      std::printf("done: %s\n", line.c_str());
      std::fflush(stdout);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lab world: %s\n", e.what());
    return 1;
  }
}
