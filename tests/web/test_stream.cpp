// The Server-Sent Events stream: live samples, campaign states, FOT nodes and tables as they
// land; a client that reconnects with Last-Event-ID misses nothing; streams are bounded.
#include <algorithm>
#include <map>
#include <mutex>
#include <set>
#include <vector>

#include "api_fixture.hpp"

using namespace hystlab;
using test::json;

namespace {
struct Event {
  std::string id, type;
  json data;
};

// A stream read on its own thread until stopped.
class StreamReader {
 public:
  StreamReader(int port, const std::string& path, const httplib::Headers& headers = {}) {
    thread_ = std::thread([this, port, path, headers] {
      httplib::Client c("127.0.0.1", port);
      c.set_read_timeout(30, 0);
      auto r = c.Get(path.c_str(), headers, [this](const char* data, std::size_t n) {
        std::lock_guard lk(mu_);
        text_.append(data, n);
        return !stop_;
      });
      std::lock_guard lk(mu_);
      status_ = r ? r->status : -1;
      done_ = true;
    });
  }
  ~StreamReader() {
    {
      std::lock_guard lk(mu_);
      stop_ = true;
    }
    thread_.join();
  }
  std::vector<Event> events() {
    std::lock_guard lk(mu_);
    std::vector<Event> out;
    std::size_t at = 0;
    for (std::size_t end; (end = text_.find("\n\n", at)) != std::string::npos; at = end + 2) {
      Event e;
      std::istringstream block(text_.substr(at, end - at));
      for (std::string line; std::getline(block, line);) {
        if (line.rfind("id: ", 0) == 0) e.id = line.substr(4);
        if (line.rfind("event: ", 0) == 0) e.type = line.substr(7);
        if (line.rfind("data: ", 0) == 0) e.data = json::parse(line.substr(6));
      }
      if (!e.type.empty()) out.push_back(e);
    }
    return out;
  }
  bool wait(const std::function<bool(const std::vector<Event>&)>& pred, double seconds = 60) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      if (pred(events())) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }
  int status() {
    std::lock_guard lk(mu_);
    return done_ ? status_ : 0;
  }

 private:
  std::mutex mu_;
  std::string text_;
  bool stop_ = false, done_ = false;
  int status_ = 0;
  std::thread thread_;
};

std::vector<Event> records(const std::vector<Event>& all) {
  std::vector<Event> out;
  for (const auto& e : all)
    if (!e.id.empty()) out.push_back(e);
  return out;
}

bool has_state(const std::vector<Event>& ev, const std::string& to) {
  return std::any_of(ev.begin(), ev.end(), [&](const Event& e) { return e.type == "campaign" && e.data["to"] == to; });
}
}  // namespace

TEST_CASE("the event stream carries samples, states, nodes and tables; Last-Event-ID resumes without gaps") {
  test::LiveDaemon live;
  const int port = live.http->port();
  StreamReader first(port, "/api/stream?rate=20");
  REQUIRE(first.wait([](const auto& ev) { return !ev.empty() && ev.front().type == "hello"; }, 10));
  auto c = live.client();
  REQUIRE(c.Post("/api/campaigns", json{{"plan", test::fot_plan(3)}}.dump(), "application/json")->status == 201);
  REQUIRE(first.wait(
      [](const auto& ev) { return has_state(ev, "completed") && std::count_if(ev.begin(), ev.end(), [](const Event& e) { return e.type == "table"; }) == 2; }));
  const auto all = first.events();
  std::vector<std::string> states;
  std::size_t nodes = 0, sample_frames = 0;
  for (const auto& e : all) {
    if (e.type == "campaign") states.push_back(e.data["to"]);
    if (e.type == "node") {
      ++nodes;
      CHECK(e.data["F"].get<double>() == doctest::Approx(e.data["force_alpha"].get<double>() - e.data["force_alpha_beta"].get<double>()));
    }
    if (e.type == "samples" && e.data["run"] == 1) {
      ++sample_frames;
      CHECK(e.data["t"].size() == e.data["force"].size());
    }
  }
  CHECK(states == std::vector<std::string>{"queued", "arming", "running", "completed"});
  CHECK(nodes == 6);
  // The run's samples reached the stream. How many frames depends on how long the campaign took
  // in wall time (1.75 s of rig time at 20 times real time, ~90 ms, unless the simulator is
  // starved: under ThreadSanitizer it once left an 8 s hole, and the stream sent 3 frames where
  // other runs sent 6-12). Their number is the scheduler's; that they come, whole, is the code's.
  CHECK(sample_frames >= 1);
  // Decimated to the asked rate: 500 Hz in, about 20 Hz out.
  std::size_t values = 0;
  double t0 = 1e300, t1 = -1e300;
  for (const auto& e : all)
    if (e.type == "samples" && e.data["run"] == 1) {
      values += e.data["t"].size();
      t0 = std::min(t0, e.data["t"].front().get<double>());
      t1 = std::max(t1, e.data["t"].back().get<double>());
    }
  const double wall = (t1 - t0) / 20.0;  // the simulator runs 20 times faster than the wall clock
  CAPTURE(values);
  CAPTURE(wall);
  CHECK(static_cast<double>(values) < 40.0 * wall + 20);

  // Reconnect after the third record: every later record arrives, once, each kind in order
  // (across kinds, records that land in one poll come grouped by kind).
  const auto recs = records(all);
  REQUIRE(recs.size() > 6);
  StreamReader second(port, "/api/stream?rate=1", {{"Last-Event-ID", recs[2].id}});
  REQUIRE(second.wait([&](const auto& ev) { return records(ev).size() >= recs.size() - 3; }, 10));
  const auto again = records(second.events());
  auto keys = [](const std::vector<Event>& ev, std::size_t from) {
    std::vector<std::pair<std::string, std::int64_t>> k;
    for (std::size_t i = from; i < ev.size(); ++i)
      k.emplace_back(ev[i].type == "node" || ev[i].type == "table" ? ev[i].type : "event", ev[i].data["id"].get<std::int64_t>());
    return k;
  };
  const auto expected = keys(recs, 3), got = keys(again, 0);
  auto sorted = [](auto v) {
    std::sort(v.begin(), v.end());
    return v;
  };
  CHECK(sorted(got) == sorted(expected));
  std::map<std::string, std::int64_t> last;
  for (const auto& [kind, id] : got) {
    CHECK(id > last[kind]);
    last[kind] = id;
  }
  CHECK(again.back().id == recs.back().id);  // the same cursor at the end
}

TEST_CASE("streams are bounded: one more than http.max_stream_clients is refused, and counted in /metrics") {
  test::LiveDaemon live([](daemon::DaemonConfig& c) { c.http.max_stream_clients = 2; });
  const int port = live.http->port();
  StreamReader a(port, "/api/stream"), b(port, "/api/stream");
  REQUIRE(a.wait([](const auto& ev) { return !ev.empty(); }, 10));
  REQUIRE(b.wait([](const auto& ev) { return !ev.empty(); }, 10));
  auto c = live.client();
  auto r = c.Get("/api/stream");
  REQUIRE(r);
  CHECK(r->status == 503);
  CHECK(json::parse(r->body)["detail"].get<std::string>().find("max_stream_clients") != std::string::npos);
  CHECK(c.Get("/metrics")->body.find("hystlab_sse_clients 2") != std::string::npos);
  CHECK(c.Get("/api/status")->status == 200);  // plain requests are still served
}
