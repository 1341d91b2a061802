// The campaign events' schema (domain/events.hpp): every kind round-trips through its struct, a
// detail of the wrong shape is refused by name, and docs/API.md lists the same kinds and fields.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>

#include "../support/build_paths.hpp"
#include "hystlab/domain/events.hpp"

namespace domain = hystlab::domain;
using nlohmann::json;

namespace {

// A value of the same JSON type as `like`, drawn from rng (text with quotes, a newline and
// non-ASCII letters: what a specimen's name may hold).
json random_like(const json& like, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> real(-1e6, 1e6);
  std::uniform_int_distribution<std::int64_t> whole(-1'000'000'000, 1'000'000'000);
  if (like.is_boolean()) return !like.get<bool>();
  if (like.is_number_unsigned()) return static_cast<std::uint64_t>(whole(rng) & 0x7fffffff);
  if (like.is_number_integer()) return whole(rng);
  if (like.is_number_float() || like.is_null()) return real(rng);
  if (like.is_string()) return "spring \"A\"\nNiTi ø" + std::to_string(whole(rng));
  if (like.is_array()) {
    json a = json::array();
    for (std::size_t i = 0; i < (like.empty() ? 3 : like.size()); ++i) a.push_back(like.empty() ? json(real(rng)) : random_like(like[i], rng));
    return a;
  }
  return json{{"overall", {{"rms_N", real(rng)}, {"max_N", real(rng)}}}};  // an object (fit's accuracy)
}

// Decoded and encoded again: the same JSON, field by field.
void round_trips(std::string_view kind, const json& detail) {
  CAPTURE(kind);
  CAPTURE(detail.dump());
  std::string error;
  const auto e = domain::decode_event(kind, detail.dump(), error);
  REQUIRE_MESSAGE(e, error);
  CHECK(error.empty());
  CHECK(domain::kind_of(*e) == kind);
  CHECK(domain::detail_json(*e) == detail);
  const auto again = domain::decode_event(kind, domain::encode(*e), error);
  REQUIRE(again);
  CHECK(domain::encode(*again) == domain::encode(*e));
}

}  // namespace

TEST_CASE("every event kind round-trips through its struct, with seeded random fields") {
  const std::uint64_t seed = 20261126;
  CAPTURE(seed);
  std::mt19937_64 rng(seed);
  std::set<std::string_view> seen;
  for (const domain::EventKind& k : domain::event_kinds()) {
    CHECK_MESSAGE(seen.insert(k.kind).second, "a kind listed twice: " << k.kind);
    if (k.kind == "command") continue;  // text, below
    std::string error;
    const auto empty = domain::decode_event(k.kind, "{}", error);  // every field at its default
    REQUIRE_MESSAGE(empty, error);
    const json defaults = domain::detail_json(*empty);
    for (int round = 0; round < 20; ++round) {
      json d = json::object();
      for (const auto& [name, v] : defaults.items()) d[name] = random_like(v, rng);
      round_trips(k.kind, d);
    }
    // What is written is the schema: no field outside the list.
    for (const auto& item : defaults.items()) {
      const std::string name = item.key();
      CHECK_MESSAGE(std::find(k.fields.begin(), k.fields.end(), name) != k.fields.end(), k.kind << "." << name);
    }
  }
  CHECK(seen.size() == std::variant_size_v<domain::CampaignEvent>);
}

TEST_CASE("the fields of one shape only: present when given, absent when not") {
  round_trips("retake", json{{"rows", {3, 4}}, {"round", 1}, {"why", "a node of each was missing"}});
  round_trips("retake", json{{"frequency_hz", 22.5}, {"attempt", 2}, {"why", "a gap in the window"}});
  round_trips("envelope", json{{"stroke_mm", {-1.0, 11.0}}, {"force_N", 2500.0}, {"speed_mm_s", 50.0}, {"accel_mm_s2", 500.0}});
  round_trips("envelope", json{{"displacement_mm", 5.0}, {"velocity_mm_s", 200.0}, {"accel_g", 10.0}, {"frequency_hz", {5.0, 200.0}}});
  round_trips(
      "control_unreached",
      json{{"frequency_hz", 21.0}, {"demand_mm", 1.0}, {"error_pct", -6.5}, {"windows", 8}, {"drive_mm", 3.2}, {"limited", true}, {"while", "measuring"}});
  round_trips("shakedown", json{{"cycle", 2},
                                {"peak_force_N", 310.0},
                                {"energy_Nmm", 52.0},
                                {"consecutive", 0},
                                {"stable", false},
                                {"damping_ratio", 0.08},
                                {"secant_stiffness_N_mm", 40.0},
                                {"peak_change_pct", -1.5},
                                {"energy_change_pct", 3.0}});
  domain::RetakeEvent frame;
  frame.rows = std::vector<std::int64_t>{7}, frame.round = 2, frame.why = "hole";
  const json j = domain::detail_json(frame);
  CHECK_FALSE(j.contains("frequency_hz"));
  CHECK_FALSE(j.contains("attempt"));
}

TEST_CASE("a command is text; a NaN is stored as null and read back as NaN") {
  std::string error;
  const auto c = domain::decode_event("command", "'pause' refused: the campaign is queued", error);
  REQUIRE(c);
  CHECK(domain::encode(*c) == "'pause' refused: the campaign is queued");
  CHECK(domain::detail_json(*c) == json("'pause' refused: the campaign is queued"));

  domain::ControlAbortEvent a{20.0, 1.0, NAN, NAN, 2.0};
  const std::string text = domain::encode(a);
  CHECK(text.find("\"base_mm\":null") != std::string::npos);
  const auto back = domain::decode_event("control_abort", text, error);
  REQUIRE(back);
  CHECK(std::isnan(std::get<domain::ControlAbortEvent>(*back).base_mm));
  CHECK(std::get<domain::ControlAbortEvent>(*back).drive_mm == 2.0);
}

TEST_CASE("a detail of the wrong shape is refused by kind and field; an unknown kind is left to the caller") {
  std::string error;
  CHECK_FALSE(domain::decode_event("quality", R"({"run": 1, "samples": "many"})", error));
  CHECK(error == "quality: field 'samples' must be a whole number");
  CHECK_FALSE(domain::decode_event("limits", R"({"displacement_mm": [1]})", error));
  CHECK(error == "limits: field 'displacement_mm' must be a pair of numbers");
  CHECK_FALSE(domain::decode_event("training", R"({"stable": "yes"})", error));
  CHECK(error == "training: field 'stable' must be true or false");
  CHECK_FALSE(domain::decode_event("record", R"({"specimen": 3})", error));
  CHECK(error == "record: field 'specimen' must be text");
  CHECK_FALSE(domain::decode_event("gap", "not json", error));
  CHECK(error == "gap: its detail is not a JSON object");
  CHECK_FALSE(domain::decode_event("state", "started by the daemon", error));
  CHECK(error.empty());
  CHECK_FALSE(domain::decode_event("from_a_newer_daemon", "{}", error));
  CHECK(error.empty());
  // An older detail without a field keeps its default; a whole number stored as 3.0 is read.
  const auto old = domain::decode_event("gaps", R"({"count": 3.0})", error);
  REQUIRE(old);
  CHECK(std::get<domain::GapsEvent>(*old).count == 3);
  CHECK(std::isnan(std::get<domain::GapsEvent>(*old).total_ms));
}

TEST_CASE("docs/API.md lists every event kind with its fields, in the order written") {
  std::ifstream in(HYSTLAB_API_DOC);
  REQUIRE(in);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string doc = ss.str();
  const std::size_t table = doc.find("<!-- event schema");
  REQUIRE(table != std::string::npos);
  std::set<std::string> documented;
  std::istringstream lines(doc.substr(table));
  std::string line;
  std::getline(lines, line);
  while (std::getline(lines, line) && (line.empty() || line[0] == '|')) {
    if (line.rfind("| `", 0) != 0) continue;
    const std::size_t k0 = 3, k1 = line.find('`', k0);
    const std::string kind = line.substr(k0, k1 - k0);
    const std::size_t f0 = line.find('|', k1) + 1, f1 = line.find('|', f0);
    std::vector<std::string> fields;
    for (std::size_t p = line.find('`', f0); p < f1; p = line.find('`', line.find('`', p + 1) + 1))
      fields.push_back(line.substr(p + 1, line.find('`', p + 1) - p - 1));
    documented.insert(kind);
    CAPTURE(kind);
    const auto& kinds = domain::event_kinds();
    const auto it = std::find_if(kinds.begin(), kinds.end(), [&](const domain::EventKind& e) { return e.kind == kind; });
    REQUIRE_MESSAGE(it != kinds.end(), "docs/API.md lists a kind the code does not have");
    CHECK(fields == std::vector<std::string>(it->fields.begin(), it->fields.end()));
  }
  for (const domain::EventKind& k : domain::event_kinds()) CHECK_MESSAGE(documented.count(std::string(k.kind)) == 1, "not in docs/API.md: " << k.kind);
}
