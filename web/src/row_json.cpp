// The JSON of stored rows, and each run's data quality in words.
#include <cmath>
#include <cstdio>

#include "routes.hpp"

namespace hystlab::web {
namespace {
std::string round_s(double s) {
  char b[32];
  std::snprintf(b, sizeof b, s < 10 ? "%.2g s" : "%.0f s", s);
  return b;
}
std::string hz(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g Hz", v);
  return b;
}
std::uint64_t count(const json& q, const char* k) { return q.value(k, std::uint64_t{0}); }

json warnings_of(const json& q) {
  json w = json::array();
  const std::uint64_t samples = count(q, "samples"), missed = count(q, "missed_deadlines");
  // A late period now and then is the host's scheduler (a bare sleep loop misses some on these
  // machines): a warning from 0.1 % of the samples.
  if (missed > 0 && static_cast<double>(missed) >= 1e-3 * static_cast<double>(std::max<std::uint64_t>(samples, 1)))
    w.push_back(std::to_string(missed) + " missed deadlines (samples not taken in time) in " + std::to_string(samples) + " samples");
  if (const auto lost = count(q, "lost_samples")) w.push_back(std::to_string(lost) + " samples lost by the controller's buffer before they were read");
  if (const auto dropped = count(q, "dropped")) w.push_back(std::to_string(dropped) + " samples not stored (the database fell behind)");
  if (const auto err = count(q, "io_errors"))
    w.push_back(std::to_string(err) + " I/O errors (" + std::to_string(count(q, "timeouts")) + " timeouts, " + std::to_string(count(q, "reconnects")) +
                " reconnects)");
  if (const auto gaps = count(q, "gaps"))
    w.push_back(std::to_string(gaps) + (gaps == 1 ? " hole" : " holes") + " in the time axis: longest " + round_s(q.value("longest_gap_s", 0.0)) + ", " +
                round_s(q.value("gap_total_s", 0.0)) + " in all");
  // A simulator faster than real time gives the plan's rate in wall time, time_scale times less
  // in rig time: expected, said beside the rate, and no warning unless that was not kept either.
  const double rate = q.value("rate_hz", 0.0), asked = q.value("requested_rate_hz", 0.0);
  const double scale = q.value("time_scale", 1.0), expected = q.value("expected_rate_hz", asked);
  if (rate > 0 && expected > 0 && std::abs(rate / expected - 1) > 0.05)
    w.push_back("stored " + hz(rate) + " of rig time; the plan asked " + hz(asked) +
                (scale > 1 ? " (" + hz(expected) + " of rig time at this simulator's time scale)" : ""));
  return w;
}
}  // namespace

json event_detail(const std::string& kind, const std::string& detail) {
  std::string error;
  if (const auto e = domain::decode_event(kind, detail, error)) return domain::detail_json(*e);
  return parse_or_text(detail);
}

json parse_or_text(const std::string& s) {
  if (s.empty()) return nullptr;
  const json j = json::parse(s, nullptr, false);
  return j.is_discarded() ? json(s) : j;
}

json node_json(const db::NodeInfo& n) {
  return {{"id", n.id},
          {"campaign", n.campaign},
          {"run", n.run},
          {"alpha", n.alpha},
          {"beta", n.beta},
          {"force_alpha", n.force_alpha},
          {"force_alpha_beta", n.force_alpha_beta},
          {"F", n.force_alpha - n.force_alpha_beta},
          {"t", n.t}};
}

json table_json(const db::TableInfo& t) {
  return {{"id", t.id},
          {"campaign", t.campaign ? json(*t.campaign) : json(nullptr)},
          {"run", t.run ? json(*t.run) : json(nullptr)},
          {"method", t.method},
          {"n", t.n},
          {"range_mm", {t.range_lo, t.range_hi}},
          {"created_at", t.created_at},
          {"accuracy", parse_or_text(t.accuracy_json)}};
}

json run_quality(db::ReadSource& store, std::int64_t campaign, std::int64_t run) {
  for (const domain::QualityEvent& e : db::events_of<domain::QualityEvent>(store, campaign)) {
    if (e.run != run) continue;
    json q = domain::detail_json(e);
    q["warnings"] = warnings_of(q);
    return q;
  }
  return nullptr;
}

json result_warnings(const json& quality) {
  json w = json::array();
  if (!quality.is_object()) return w;
  if (const auto gaps = count(quality, "gaps"))
    w.push_back("computed over a run with " + std::to_string(gaps) + (gaps == 1 ? " hole" : " holes") + " in its data (longest " +
                round_s(quality.value("longest_gap_s", 0.0)) + ")");
  if (const auto lost = count(quality, "lost_samples")) w.push_back("computed over a run that lost " + std::to_string(lost) + " samples");
  return w;
}

}  // namespace hystlab::web
