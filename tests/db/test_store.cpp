// The SQLite store: schema, campaigns and events, samples and overviews, the writer thread,
// and kill -9 at any moment.
#include <doctest/doctest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <thread>

#include "../support/build_paths.hpp"
#include "../support/temp_dir.hpp"
#include "hystlab/db/sample_writer.hpp"
#include "hystlab/db/schema.hpp"
#include "hystlab/db/store.hpp"

extern char** environ;
namespace fs = std::filesystem;
using namespace hystlab::db;
using namespace hystlab::domain;

namespace {
struct TempDb {
  hystlab::test_support::TempDir tmp{"db"};
  fs::path dir = tmp.path();
  std::string path = (dir / "hystlab.db").string();
};

std::int64_t campaign_with_run(Store& s) {
  const auto rig = s.upsert_rig("frame", "{}", "2026-01-01T00:00:00Z");
  const auto c = s.create_campaign(rig, CampaignKind::fot, "{}", "2026-01-01T00:00:00Z");
  return s.add_run(c, "2026-01-01T00:00:00Z", 1.7e9, 0.0);
}
}  // namespace

TEST_CASE("schema: a new file is migrated; a newer one is refused, not guessed at") {
  TempDb t;
  {
    Store s(t.path);
    CHECK(schema_version(s.database()) == kSchemaVersion);
    s.database().exec("PRAGMA user_version=99");
  }
  CHECK_THROWS_WITH_AS(Store(t.path), doctest::Contains("newer than this hystlab"), DbError);
}

TEST_CASE("a new database file, and its WAL, are the owner's alone (0600)") {
  TempDb t;
  {
    Store s(t.path);
    (void)campaign_with_run(s);
    for (const std::string& f : {t.path, t.path + "-wal"}) {
      CAPTURE(f);
      REQUIRE(fs::exists(f));
      CHECK((fs::status(f).permissions() & fs::perms::all) == (fs::perms::owner_read | fs::perms::owner_write));
    }
  }
  // An existing file keeps the mode its owner gave it.
  fs::permissions(t.path, fs::perms::group_read, fs::perm_options::add);
  Store again(t.path);
  CHECK((fs::status(t.path).permissions() & fs::perms::group_read) != fs::perms::none);
}

TEST_CASE("campaigns: every transition is stored with time and reason; a crash leaves them interrupted") {
  TempDb t;
  Store s(t.path);
  const auto rig = s.upsert_rig("frame", "{\"transport\":\"modbus-tcp\"}", "t0");
  CHECK(s.upsert_rig("frame", "{}", "t1") == rig);  // same name, same rig
  const auto c = s.create_campaign(rig, CampaignKind::fot, "{\"n\":12}", "t0");
  s.transition(c, CampaignState::arming, "operator", "t1");
  s.transition(c, CampaignState::running, "armed", "t2");
  CHECK(s.campaign(c)->state == CampaignState::running);
  CHECK(s.mark_interrupted("t3") == 1);
  CHECK(s.campaign(c)->state == CampaignState::interrupted);
  const auto ev = s.events(c);
  REQUIRE(ev.size() == 4);
  CHECK(ev[0].to_state == "queued");
  CHECK(ev[3].from_state == "running");
  CHECK(ev[3].to_state == "interrupted");
  CHECK(ev[3].at == "t3");
  CHECK_THROWS_AS(s.transition(999, CampaignState::running, "", "t"), DbError);
}

TEST_CASE("campaign states and kinds: enums inside, their stored text round-trips; text this program never wrote is named") {
  for (const CampaignState st : kCampaignStates) {
    CAPTURE(to_string(st));
    REQUIRE(campaign_state_from(to_string(st)).has_value());
    CHECK(*campaign_state_from(to_string(st)) == st);
  }
  CHECK_FALSE(campaign_state_from("Completed").has_value());
  CHECK_FALSE(campaign_state_from("").has_value());
  for (const CampaignKind k : {CampaignKind::fot, CampaignKind::waveform, CampaignKind::sine}) CHECK(*campaign_kind_from(to_string(k)) == k);
  CHECK_FALSE(campaign_kind_from("sweep").has_value());
  CHECK(is_final(CampaignState::completed));
  CHECK_FALSE(is_final(CampaignState::interrupted));  // an interrupted campaign can resume

  TempDb t;
  Store s(t.path);
  const auto rig = s.upsert_rig("frame", "{}", "t0");
  const auto c = s.create_campaign(rig, CampaignKind::sine, "{}", "t0");
  CHECK(s.campaign(c)->kind == CampaignKind::sine);
  s.transition(c, CampaignState::paused, "operator", "t1");
  const auto counts = s.campaign_counts();
  REQUIRE(counts.size() == 1);
  CHECK(counts[0].first == CampaignState::paused);
  CHECK(counts[0].second == 1);
  {  // another tool wrote a state of its own
    Statement st(s.database(), "UPDATE campaigns SET state = 'finished' WHERE id = ?");
    st.bind(1, c);
    st.step();
  }
  CHECK_THROWS_WITH_AS((void)s.campaign(c), doctest::Contains("unknown state 'finished'"), DbError);
  CHECK_THROWS_WITH_AS((void)s.campaign_counts(), doctest::Contains("unknown campaign state 'finished'"), DbError);
}

TEST_CASE("transactions roll back unless committed") {
  TempDb t;
  Store s(t.path);
  const auto run = campaign_with_run(s);
  try {
    Transaction tx(s.database());
    const SampleRow r{run, 0, 0.0, 0, 1, 2, 0};
    s.insert_samples(std::span(&r, 1));
    throw std::runtime_error("boom");
  } catch (const std::runtime_error&) {
  }
  CHECK(s.sample_count(run) == 0);
  CHECK(s.max_seq(run) == -1);
}

TEST_CASE("overview: min and max per bucket, so no peak is lost, from blocks or raw samples") {
  TempDb t;
  Store s(t.path);
  const auto run = campaign_with_run(s);
  std::vector<SampleRow> rows;
  for (std::int64_t k = 0; k < 200'000; ++k)
    rows.push_back({run, k, static_cast<double>(k) * 1e-3, 0, std::sin(static_cast<double>(k) * 1e-3), k == 123'457 ? 999.0 : 1.0, 0});
  {
    Transaction tx(s.database());
    s.insert_samples(rows);
    tx.commit();
  }
  CHECK(s.sample_count(run) == 200'000);
  const auto wide = s.overview(run, 0, 200, 100);  // from the block summaries
  REQUIRE_FALSE(wide.empty());
  CHECK(wide.size() <= 100);
  double fmax = 0;
  std::int64_t n = 0;
  for (const auto& b : wide) fmax = std::max(fmax, b.force_max), n += b.n;
  CHECK(fmax == 999.0);  // the single spike survives decimation
  CHECK(n == 200'000);
  const auto narrow = s.overview(run, 123.0, 124.0, 10);  // from the raw samples
  REQUIRE(narrow.size() == 10);
  CHECK(narrow[4].force_max == 999.0);
  CHECK(narrow[0].t_min >= 123.0);
  CHECK(narrow.back().t_max <= 124.0);
  CHECK(s.overview(run, 500, 600, 10).empty());
  CHECK(s.integrity_check() == "ok");
}

TEST_CASE("writer: batches committed off the caller's thread; a full ring is counted") {
  TempDb t;
  std::int64_t run = 0;
  {
    Store s(t.path);
    run = campaign_with_run(s);
  }
  {
    SampleWriter w(t.path, WriterOptions{1U << 12, 0.05, 1000, true});
    for (std::int64_t k = 0; k < 3000; ++k) REQUIRE(w.try_push(SampleRow{run, k, static_cast<double>(k), 0, 0, 0, 0}));
    w.flush();
    const WriterStats st = w.stats();
    CHECK(st.written == 3000);
    CHECK(st.acknowledged_seq == 2999);
    CHECK(st.commits >= 3);  // max_batch 1000
    CHECK(st.dropped_full == 0);
    // Far more than the ring holds, faster than any disk: the overflow is counted.
    std::int64_t accepted = 0;
    for (std::int64_t k = 3000; k < 3000 + 200'000; ++k) accepted += w.try_push(SampleRow{run, k, static_cast<double>(k), 0, 0, 0, 0}) ? 1 : 0;
    w.flush();
    const WriterStats after = w.stats();
    CHECK(after.dropped_full > 0);
    CHECK(after.dropped_full + static_cast<std::uint64_t>(accepted) == 200'000);
    CHECK(after.written == 3000 + static_cast<std::uint64_t>(accepted));
  }
  Store s(t.path);
  CHECK(s.integrity_check() == "ok");
}

TEST_CASE("kill -9 at random moments: integrity ok, every acknowledged sample present") {
  TempDb t;
  { Store s(t.path); }
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> wait_ms(150, 700);
  for (int round = 1; round <= 3; ++round) {
    CAPTURE(round);
    int out[2];
    REQUIRE(pipe(out) == 0);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, out[1], 1);
    std::string exe = HYSTLAB_CRASH_WRITER, db = t.path, run = std::to_string(round);
    char* argv[] = {exe.data(), db.data(), run.data(), nullptr};
    pid_t pid = 0;
    REQUIRE(posix_spawn(&pid, exe.c_str(), &fa, nullptr, argv, environ) == 0);
    posix_spawn_file_actions_destroy(&fa);
    close(out[1]);
    // The random moment is counted from the first committed batch, so that a slow host (a
    // sanitizer build under load) cannot make a round vacuous.
    std::string text;
    char buf[4096];
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    auto committed = [](const std::string& out_text) {  // an "ack N" with N >= 0 (-1: nothing yet)
      for (auto p = out_text.find("ack "); p != std::string::npos; p = out_text.find("ack ", p + 1))
        if (p + 4 < out_text.size() && std::isdigit(static_cast<unsigned char>(out_text[p + 4]))) return true;
      return false;
    };
    while (!committed(text) && std::chrono::steady_clock::now() < give_up) {
      const ssize_t n = read(out[0], buf, sizeof buf);
      if (n <= 0) break;
      text.append(buf, static_cast<std::size_t>(n));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(wait_ms(rng)));
    kill(pid, SIGKILL);
    int st = 0;
    waitpid(pid, &st, 0);
    // The last acknowledgement printed before the kill.
    for (ssize_t n; (n = read(out[0], buf, sizeof buf)) > 0;) text.append(buf, static_cast<std::size_t>(n));
    close(out[0]);
    const auto pos = text.rfind("ack ");
    REQUIRE(pos != std::string::npos);
    const long long acked = std::stoll(text.substr(pos + 4));
    Store s(t.path);
    CHECK(s.integrity_check() == "ok");
    CHECK(acked > 0);
    CHECK(s.max_seq(round) >= acked);
    CHECK(s.sample_count(round) == s.max_seq(round) + 1);  // no holes: batches land whole
  }
}
