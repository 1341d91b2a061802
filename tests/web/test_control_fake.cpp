// The web layer against a fake daemon: hystlab::web needs nothing of the daemon but its interface
// (hystlab/control/daemon_interface.hpp). The fake records what it is asked and answers with
// values the test chose; the HTTP client is real, and so is the database the reads come from.
#include <doctest/doctest.h>

#include <mutex>

#include "api_fixture.hpp"
#include "hystlab/control/daemon_interface.hpp"
#include "hystlab/db/store.hpp"

using namespace hystlab;
using test::json;

namespace {
class FakeDaemon final : public control::DaemonInterface {
 public:
  explicit FakeDaemon(std::string db) : db_(std::move(db)) {}
  std::size_t rig_count() const noexcept override { return 1; }
  control::RigInfo rig_info(std::size_t) const override { return {7, "fake frame", "a fake", domain::RigKind::load_frame, true}; }
  control::RigSupervision rig_supervision(std::size_t) const override {
    control::RigSupervision s;
    s.state = estopped ? "estopped" : "idle";
    s.latched = estopped;
    s.latch_reason = estopped ? "operator e-stop" : "";
    return s;
  }
  control::LinkHealth rig_health(std::size_t) const override {
    control::LinkHealth h;
    h.reads = 1234;
    h.errors = {{"timeout", 13}, {"crc_error", 2}};
    h.latency_histogram_us = {1, 2, 3};
    return h;
  }
  control::AcquisitionCounters rig_counters(std::size_t) const override { return {5000, 1979, 4, 0, 0, 0}; }
  std::size_t rig_index(const std::string& name, std::string_view) const override {
    if (!name.empty() && name != "fake frame") throw std::invalid_argument("rig: no rig named '" + name + "'");
    return 0;
  }
  control::CommandOutcome rig_command(std::size_t, control::RigCommand c) override {
    estopped = c == control::RigCommand::estop;
    return {control::CommandOutcome::Result::done, estopped, true, estopped ? "estopped" : "idle", "", 0.0};
  }
  std::uint64_t live_head(std::size_t) const noexcept override { return 3; }
  std::uint64_t read_live(std::size_t, std::uint64_t from, std::size_t, std::vector<control::LiveSample>& out, std::uint64_t*) const override {
    for (std::uint64_t i = from; i < 3; ++i) out.push_back(control::LiveSample::of(0, static_cast<double>(i), domain::FrameSample{1, 2.5, 42.0}, 0, 5));
    return 3;
  }
  std::int64_t submit(const std::string&, const nlohmann::json& plan) override {
    if (!plan.contains("kind")) throw control::PlanError("kind", "plan: kind is required");
    db::Store s(db_);
    return s.create_campaign(s.upsert_rig("fake frame", "{}", "t"), domain::CampaignKind::fot, plan.dump(), "t");
  }
  control::PlanPreview preview(const std::string&, const nlohmann::json&, models::HysteresisModel*) const override { return {}; }
  control::CommandOutcome command(std::int64_t campaign, control::CampaignCommand c) override {
    std::lock_guard lk(mu);
    commands.emplace_back(campaign, c);
    return {control::CommandOutcome::Result::done, false, false, "running", "", 0.0};
  }
  // A record change: kept, written as the daemon writes it (a "record" event), or refused by field.
  void set_record(std::int64_t campaign, const nlohmann::json& changes) override {
    if (changes.contains("colour")) throw control::PlanError("colour", "colour is not part of a campaign's record (specimen, notes)");
    std::lock_guard lk(mu);
    records.emplace_back(campaign, changes);
    db::Store(db_).add_event(campaign, domain::RecordEvent{changes.value("specimen", ""), changes.value("notes", "")}, "2026-01-01T00:00:00.000Z");
  }
  control::WriterCounters writer() const override { return {99, 0, 0, 1}; }
  double uptime_s() const noexcept override { return 12.5; }
  std::string db_path() const override { return db_; }
  void keep_off_acquisition_cpu(bool) const noexcept override {}

  std::string db_;
  std::atomic<bool> estopped{false};
  std::mutex mu;
  std::vector<std::pair<std::int64_t, control::CampaignCommand>> commands;
  std::vector<std::pair<std::int64_t, nlohmann::json>> records;
};
}  // namespace

TEST_CASE("the web layer runs on the daemon's interface alone: snapshots, commands and plans go through it") {
  test::TempDir dir;
  const std::string db = (dir.path / "fake.db").string();
  { db::Store create(db); }
  FakeDaemon fake(db);
  control::HttpConfig cfg;
  cfg.port = 0;
  web::HttpApi http(fake, cfg);
  httplib::Client c("127.0.0.1", http.port());
  c.set_read_timeout(10, 0);

  SUBCASE("the rig panel shows the interface's values") {
    auto r = c.Get("/api/rigs/fake%20frame");
    REQUIRE(r);
    REQUIRE(r->status == 200);
    const json j = json::parse(r->body);
    CHECK(j["id"] == 7);
    CHECK(j["missed_deadlines"] == 1979);
    CHECK(j["health"]["errors"]["timeout"] == 13);
    CHECK(j["health"]["reads"] == 1234);
    CHECK(j["sample"]["force_N"] == 42.0);
    auto m = c.Get("/metrics");
    REQUIRE(m);
    CHECK(m->body.find("hystlab_rig_errors_total{rig=\"fake frame\",kind=\"timeout\"} 13") != std::string::npos);
    CHECK(m->body.find("hystlab_rig_transaction_seconds_bucket{rig=\"fake frame\",le=\"+Inf\"} 6") != std::string::npos);
  }
  SUBCASE("e-stop reaches the interface, and the panel shows the latch") {
    auto r = c.Post("/api/rigs/fake%20frame/estop", "", "application/json");
    REQUIRE(r);
    CHECK(r->status == 200);
    CHECK(json::parse(r->body)["result"] == "done");
    CHECK(fake.estopped);
    CHECK(json::parse(c.Get("/api/rigs/fake%20frame")->body)["latched"] == true);
  }
  SUBCASE("a campaign is submitted through the interface; a bodiless command reaches it as an enum; an unknown one does not") {
    auto r = c.Post("/api/campaigns", json{{"plan", {{"kind", "fot"}, {"range_mm", {0, 4}}, {"subdivisions", 2}}}}.dump(), "application/json");
    REQUIRE(r);
    REQUIRE(r->status == 201);
    const auto id = json::parse(r->body)["id"].get<std::int64_t>();
    const json created = json::parse(r->body);
    CHECK(created["state"] == "queued");
    CHECK(created["commands"] == json::array({"abort", "estop"}));  // what the page offers for a queued one
    CHECK(created["active"] == false);
    CHECK(created["final"] == false);
    httplib::Headers none;
    auto a = c.Post("/api/campaigns/" + std::to_string(id) + "/abort", none, "", "");
    REQUIRE(a);
    CHECK(a->status == 200);  // the fake says done
    auto bad = c.Post("/api/campaigns/" + std::to_string(id) + "/abort_all", none, "", "");
    REQUIRE(bad);
    CHECK(bad->status == 404);
    std::lock_guard lk(fake.mu);
    REQUIRE(fake.commands.size() == 1);
    CHECK(fake.commands[0].first == id);
    CHECK(fake.commands[0].second == control::CampaignCommand::abort);
  }
  SUBCASE("a campaign's specimen and notes change through the interface; a field it refuses is named as the body's") {
    auto r =
        c.Post("/api/campaigns", json{{"plan", {{"kind", "fot"}, {"range_mm", {0, 4}}, {"subdivisions", 2}, {"specimen", "S-1"}}}}.dump(), "application/json");
    REQUIRE(r);
    REQUIRE(r->status == 201);
    const std::string id = std::to_string(json::parse(r->body)["id"].get<std::int64_t>());
    CHECK(json::parse(r->body)["specimen"] == "S-1");  // from the plan, as submitted
    auto ok = c.Post("/api/campaigns/" + id + "/record", json{{"specimen", "S-2"}, {"notes", "reseated"}}.dump(), "application/json");
    REQUIRE(ok);
    CHECK(ok->status == 200);
    const json after = json::parse(ok->body);
    CHECK(after["specimen"] == "S-2");
    CHECK(after["notes"] == "reseated");
    CHECK(after["record_changed_at"] == "2026-01-01T00:00:00.000Z");
    auto bad = c.Post("/api/campaigns/" + id + "/record", json{{"colour", "red"}}.dump(), "application/json");
    REQUIRE(bad);
    CHECK(bad->status == 400);
    CHECK(json::parse(bad->body)["field"] == "colour");
    auto missing = c.Post("/api/campaigns/999/record", json{{"notes", "x"}}.dump(), "application/json");
    REQUIRE(missing);
    CHECK(missing->status == 404);
    std::lock_guard lk(fake.mu);
    REQUIRE(fake.records.size() == 1);
    CHECK(fake.records[0].second["notes"] == "reseated");
  }
  SUBCASE("a plan the interface refuses is a 400 naming the plan's field") {
    auto r = c.Post("/api/campaigns", json{{"plan", {{"range_mm", {0, 4}}}}}.dump(), "application/json");
    REQUIRE(r);
    CHECK(r->status == 400);
    CHECK(json::parse(r->body)["field"] == "plan.kind");
  }
  SUBCASE("answers are never Brotli (the library's default quality took seconds per plot), gzip when asked") {
    auto r = c.Get("/api/rigs", httplib::Headers{{"Accept-Encoding", "gzip, deflate, br"}});
    REQUIRE(r);
    CHECK(r->status == 200);
    CHECK(r->get_header_value("Content-Encoding") == "gzip");
    CHECK(json::parse(r->body).size() == 1);  // decoded, whole
    r = c.Get("/api/rigs", httplib::Headers{{"Accept-Encoding", "br;q=1.0"}});
    REQUIRE(r);
    CHECK(r->status == 200);
    CHECK(r->get_header_value("Content-Encoding").empty());
  }
  SUBCASE("a state filter that is no campaign state is a 400 naming it") {
    auto r = c.Get("/api/campaigns?state=finished");
    REQUIRE(r);
    CHECK(r->status == 400);
    CHECK(r->body.find("'finished' is not a campaign state") != std::string::npos);
  }
  http.stop();
}

TEST_CASE("the commands a campaign's state admits are those the daemon carries out") {
  using C = control::CampaignCommand;
  using S = domain::CampaignState;
  CHECK(control::commands_for(S::running) == std::vector<C>{C::pause, C::abort, C::estop});
  CHECK(control::commands_for(S::paused) == std::vector<C>{C::resume, C::abort, C::estop});
  CHECK(control::commands_for(S::held) == std::vector<C>{C::resume, C::abort, C::estop});
  CHECK(control::commands_for(S::interrupted) == std::vector<C>{C::resume, C::abort, C::estop});
  for (const S s : {S::completed, S::aborted, S::failed}) CHECK(control::commands_for(s).empty());
  for (const S s : domain::kCampaignStates) {
    CAPTURE(domain::to_string(s));
    for (const C c : control::commands_for(s)) CHECK(control::campaign_command_from(domain::to_string(c)) == c);
  }
}
