// Every rig live over MQTT (issue 26, docs/LAB.md): the publisher against Debian's mosquitto on
// a loopback port, observed by mosquitto_sub, a real client in its own process. The daemon is a
// fake fed at 1 kHz (tests/lab/fake_daemon.hpp), except where a real hystlabd is killed.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "fake_daemon.hpp"
#include "hystlab/db/store.hpp"
#include "hystlab/lab/mqtt_publisher.hpp"
#include "mosquitto_broker.hpp"

using namespace hystlab;
using nlohmann::json;
using test_support::FakeDaemon;
using test_support::MosquittoBroker;
using test_support::Subscriber;
using test_support::TempDir;
using test_support::wait_until;

namespace {
lab::LabConfig lab_for(int port) {
  lab::LabConfig c;
  c.enabled = c.has_mqtt = true;
  c.name = "test-lab", c.daemon = "pc 1";
  c.mqtt.port = port;
  c.mqtt.client_id = "hystlabd-test";
  c.mqtt.keepalive_s = 5;
  return c;
}

// A fresh store (the events table the publisher reads), with the rig the fake calls rig 0.
std::string make_store(const TempDir& dir) {
  const std::string path = (dir / "lab.db").string();
  db::Store s(path);
  return path;
}

const std::string kPrefix = "hystlab/test-lab/pc 1";
const std::string kFrame = kPrefix + "/frame%2F1 %23a";  // the rig "frame/1 #a", escaped

json last_json(const std::vector<Subscriber::Message>& ms) { return ms.empty() ? json() : json::parse(ms.back().payload); }
}  // namespace

TEST_CASE("a rig's name is one topic level: '/', '+', '#', '%' and control characters escaped as %XX") {
  CHECK(lab::topic_level("frame 1") == "frame 1");
  CHECK(lab::topic_level("frame/1 #a") == "frame%2F1 %23a");
  CHECK(lab::topic_level("a+b%c") == "a%2Bb%25c");
  CHECK(lab::topic_level(std::string("x\ny", 3)) == "x%0Ay");
  CHECK(lab::topic_level("Prüfstand") == "Prüfstand");  // UTF-8 as is
}

TEST_CASE("a bad lab.mqtt config is one clear error naming the field") {
  const auto error_of = [](const json& mqtt) {
    try {
      (void)lab::parse_lab_config(json{{"name", "l"}, {"daemon", "d"}, {"mqtt", mqtt}}, "/tmp");
    } catch (const lab::LabConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(error_of({{"password", "secret"}}).find("lab.mqtt.password is refused") != std::string::npos);
  CHECK(error_of({{"port", 0}}).find("lab.mqtt.port must be a port number") != std::string::npos);
  CHECK(error_of({{"live_rate_hz", 0}}).find("lab.mqtt.live_rate_hz") != std::string::npos);
  CHECK(error_of({{"keepalive_s", 1}}).find("lab.mqtt.keepalive_s") != std::string::npos);
  CHECK(error_of({{"cert_file", "c.pem"}, {"key_file", "k.pem"}}).find("lab.mqtt.cert_file is given without lab.mqtt.ca_file") != std::string::npos);
  CHECK(error_of({{"ca_file", "/nonexistent/ca.pem"}}).find("lab.mqtt.ca_file names '/nonexistent/ca.pem', which cannot be read") != std::string::npos);
  CHECK(error_of({{"host", "broker.lab"}}) == "no error");
}

// A broker, a fake daemon with two rigs (one name to escape) and a publisher, connected.
struct Running {
  TempDir dir{"mqtt"};
  MosquittoBroker broker;
  FakeDaemon fake{{"frame/1 #a", "shaker"}, make_store(dir)};
  lab::MqttPublisher pub{fake, lab_for(broker.port()), fake.db_path()};
  Running() {
    pub.start();
    REQUIRE(wait_until([&] { return pub.status().connected && pub.status().published >= 3; }, 10));
  }
};

TEST_CASE("state and online are retained for a subscriber that comes later; a clean stop says offline itself") {
  Running r;
  Subscriber later(r.broker.port(), {kPrefix + "/status", kPrefix + "/+/state"});
  REQUIRE(wait_until([&] { return later.on(kFrame + "/state").size() == 1 && later.on(kPrefix + "/status").size() == 1; }, 10));
  CHECK(later.on(kFrame + "/state")[0].retained);
  const json state = last_json(later.on(kFrame + "/state"));
  CHECK(state["rig"] == "frame/1 #a");
  CHECK(state["state"] == "idle");
  CHECK(state["latched"] == false);
  CHECK(state["campaign"].is_null());
  const json online = last_json(later.on(kPrefix + "/status"));
  CHECK(later.on(kPrefix + "/status")[0].retained);
  CHECK(online["state"] == "online");
  CHECK(online["version"].is_string());
  CHECK(online["rigs"] == json::array({"frame/1 #a", "shaker"}));
  CHECK(later.on(kPrefix + "/shaker/state").size() == 1);

  r.pub.stop();  // no will: the client said DISCONNECT, after its own "offline"
  Subscriber after(r.broker.port(), {kPrefix + "/status"});
  REQUIRE(wait_until([&] { return !after.on(kPrefix + "/status").empty(); }, 10));
  CHECK(after.on(kPrefix + "/status")[0].retained);
  CHECK(last_json(after.on(kPrefix + "/status"))["state"] == "offline");
  CHECK(last_json(after.on(kPrefix + "/status"))["reason"] == "stopped");
  CHECK(!r.pub.status().connected);
  CHECK(r.pub.status().dropped == 0);
}

// The batches of run 42 the subscriber saw.
std::vector<json> batches_of_run(const Subscriber& s, int run) {
  std::vector<json> out;
  for (const auto& m : s.on(kFrame + "/live"))
    if (json b = json::parse(m.payload); b["run"] == run) out.push_back(b);
  return out;
}

TEST_CASE("a subscriber receives every live batch of a run in order, samples contiguous; the state follows the run and the latch") {
  Running r;
  Subscriber live(r.broker.port(), {kFrame + "/live", kFrame + "/state"});
  REQUIRE(wait_until([&] { return !live.on(kFrame + "/state").empty(); }, 10));  // subscribed
  r.fake.set_state("running", false, 7, 42);
  REQUIRE(wait_until([&] { return last_json(live.on(kFrame + "/state"))["state"] == "running"; }, 10));
  const json running = last_json(live.on(kFrame + "/state"));
  CHECK(running["campaign"]["id"] == 7);
  CHECK(running["campaign"]["run"] == 42);
  REQUIRE(wait_until([&] { return batches_of_run(live, 42).size() >= 20; }, 20));  // 20 a second: about 1 s
  r.fake.set_state("estopped", true);
  REQUIRE(wait_until([&] { return last_json(live.on(kFrame + "/state"))["latched"] == true; }, 10));
  CHECK(last_json(live.on(kFrame + "/state"))["latch_reason"] == "operator e-stop");

  const std::vector<json> batches = batches_of_run(live, 42);
  std::uint64_t samples = 0;
  for (std::size_t k = 0; k < batches.size(); ++k) {
    const json& b = batches[k];
    CHECK(b["lost"] == 0);
    CHECK(b["columns"] == json::array({"t", "mono_s", "command_mm", "displacement_mm", "force_N"}));
    const auto first = b["first"].get<std::uint64_t>();
    for (std::size_t i = 0; i < b["samples"].size(); ++i) CHECK(b["samples"][i][0].get<double>() == doctest::Approx(static_cast<double>(first + i) / 1000));
    samples += b["samples"].size();
    if (k == 0) continue;
    CHECK(b["seq"].get<std::uint64_t>() == batches[k - 1]["seq"].get<std::uint64_t>() + 1);
    CHECK(first == batches[k - 1]["first"].get<std::uint64_t>() + batches[k - 1]["samples"].size());
  }
  CHECK(samples >= 900);
}

TEST_CASE("the events table's new rows reach the rig's event topic, in id order") {
  Running r;
  Subscriber events(r.broker.port(), {kFrame + "/event", kPrefix + "/status"});
  REQUIRE(wait_until([&] { return !events.on(kPrefix + "/status").empty(); }, 10));  // subscribed
  {
    db::Store s(r.fake.db_path());
    const auto campaign = s.create_campaign(s.upsert_rig("frame/1 #a", "{}", "t"), domain::CampaignKind::fot, "{}", "t");
    s.add_event(campaign, domain::RecordEvent{"S-1", "seated"}, "2026-01-01T00:00:00.000Z");
  }
  REQUIRE(wait_until([&] { return events.on(kFrame + "/event").size() >= 2; }, 10));
  const json submitted = json::parse(events.on(kFrame + "/event")[0].payload), record = json::parse(events.on(kFrame + "/event")[1].payload);
  CHECK(submitted["kind"] == "state");
  CHECK(submitted["to"] == "queued");
  CHECK(submitted["rig"] == "frame/1 #a");
  CHECK(record["kind"] == "record");
  CHECK(record["detail"]["specimen"] == "S-1");
  CHECK(record["id"].get<std::int64_t>() > submitted["id"].get<std::int64_t>());
}

TEST_CASE("a broker stopped and started again: drops counted, reconnected, state and online published again, the reads kept their pace") {
  TempDir dir("mqtt");
  MosquittoBroker broker;
  FakeDaemon fake({"frame/1 #a", "shaker"}, make_store(dir));
  lab::LabConfig cfg = lab_for(broker.port());
  cfg.mqtt.queue_limit = 10;  // half a second of live batches
  lab::MqttPublisher pub(fake, cfg, fake.db_path());
  pub.start();
  REQUIRE(wait_until([&] { return pub.status().connected; }, 10));

  broker.stop();
  (void)fake.max_read_gap_s();
  REQUIRE(wait_until([&] { return !pub.status().connected; }, 10));
  REQUIRE(wait_until([&] { return pub.status().dropped > 0; }, 10));
  const auto t0 = std::chrono::steady_clock::now();
  const lab::MqttStatus down = pub.status();
  // status() never waits on the broker (a wait would be its connect's seconds; 1 s leaves room
  // for a frozen shared machine and ThreadSanitizer)
  CHECK(std::chrono::steady_clock::now() - t0 < std::chrono::seconds(1));
  CHECK(down.queued <= 10);
  CHECK(!down.last_error.empty());
  INFO("last error: " << down.last_error);
  fake.set_state("estopped", true);  // a change while down: published once the broker is back

  broker.start();
  REQUIRE(wait_until([&] { return pub.status().connected && pub.status().reconnects == 1; }, 15));
  Subscriber fresh(broker.port(), {kPrefix + "/status", kPrefix + "/+/state"});
  // The broker lost every retained message (no persistence): these are the publisher's again,
  // the unchanged shaker's state too.
  REQUIRE(wait_until([&] { return !fresh.on(kPrefix + "/status").empty() && !fresh.on(kFrame + "/state").empty(); }, 10));
  CHECK(last_json(fresh.on(kPrefix + "/status"))["state"] == "online");
  CHECK(last_json(fresh.on(kFrame + "/state"))["latched"] == true);
  CHECK(wait_until([&] { return !fresh.on(kPrefix + "/shaker/state").empty(); }, 5));
  // The publisher read the live ring at its pace all along (20 a second), and lost nothing of it.
  CHECK(fake.max_read_gap_s() < 2.0);  // 0.05 s a batch; a blocked reader would show the broker's whole outage
  CHECK(pub.status().lost_samples == 0);
  CHECK(pub.status().connect_attempts >= 2);
}

TEST_CASE("a broker with a password file: the right password connects, a wrong one is refused and said so") {
  TempDir dir("mqtt");
  MosquittoBroker broker("rig-pc", "s3cret");
  FakeDaemon fake({"frame/1 #a"}, make_store(dir));
  lab::LabConfig good = lab_for(broker.port());
  good.mqtt.username = "rig-pc", good.mqtt.password = "s3cret";
  lab::MqttPublisher ok(fake, good, fake.db_path());
  ok.start();
  CHECK(wait_until([&] { return ok.status().connected; }, 10));

  lab::LabConfig bad = good;
  bad.mqtt.password = "wrong", bad.mqtt.client_id = "hystlabd-wrong";
  lab::MqttPublisher refused(fake, bad, fake.db_path());
  refused.start();
  REQUIRE(wait_until([&] { return refused.status().last_error.find("refused") != std::string::npos; }, 10));
  CHECK(refused.status().last_error.find("not authorised") != std::string::npos);
  CHECK(!refused.status().connected);
}

TEST_CASE("hystlabd with lab.mqtt: a broker down at start does not stop it; killed, the broker publishes its will: offline") {
  const int port = test_support::free_port();  // the broker starts after the daemon
  const json config{{"rigs", json::array({{{"name", "sim frame"}, {"simulate", {{"time_scale", 10}}}}})},
                    {"lab", {{"name", "test-lab"}, {"daemon", "pc 1"}, {"mqtt", {{"host", "127.0.0.1"}, {"port", port}, {"keepalive_s", 5}}}}}};
  test_support::DaemonProcess daemon(config.dump());
  MosquittoBroker broker({}, {}, port);
  Subscriber sub(broker.port(), {kPrefix + "/status", kPrefix + "/sim frame/state"});
  INFO(daemon.log());
  REQUIRE(wait_until([&] { return last_json(sub.on(kPrefix + "/status"))["state"] == "online"; }, 20));
  CHECK(wait_until([&] { return !sub.on(kPrefix + "/sim frame/state").empty(); }, 10));
  daemon.kill9();
  REQUIRE(wait_until([&] { return last_json(sub.on(kPrefix + "/status"))["state"] == "offline"; }, 15));
  CHECK(last_json(sub.on(kPrefix + "/status"))["reason"] == "connection lost (the broker's will)");
}
