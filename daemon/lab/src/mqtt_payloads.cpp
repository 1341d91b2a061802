#include "mqtt_payloads.hpp"

#include <chrono>
#include <ctime>

#include "hystlab/domain/signals.hpp"

#ifndef HYSTLAB_VERSION
#define HYSTLAB_VERSION "unknown"
#endif

namespace hystlab::lab::detail {
using nlohmann::json;

std::string utc_now() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t secs = std::chrono::system_clock::to_time_t(now);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char buf[80];  // room for any int GCC -O2 may see in the fields (-Wformat-truncation)
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec,
                static_cast<int>(ms));
  return buf;
}

json state_json(const control::RigInfo& info, const control::RigSupervision& s, const control::AcquisitionCounters& a, std::int64_t nodes) {
  json j{{"rig", info.name},
         {"kind", info.kind == domain::RigKind::shaker ? "shaker" : "load_frame"},
         {"state", s.state},
         {"latched", s.latched},
         {"latch_reason", s.latch_reason},
         {"resetting", s.resetting},
         {"recovering", s.recovering},
         {"fault", {{"code", s.fault_code}, {"text", s.fault_text}, {"latched_code", s.latched_fault_code}}},
         {"link_losses", s.link_losses}};
  if (a.campaign != 0) {
    // Progress as the daemon's interface knows it: the loop's phase, and for a FOT campaign the
    // nodes identified so far (rows of fot_nodes). Nothing that changes every sample: a change of
    // this document is what publishes it again.
    json progress{{"phase", a.phase}};
    if (nodes >= 0) progress["nodes"] = nodes;
    j["campaign"] = {{"id", a.campaign}, {"run", a.run}, {"sample_rate_hz", a.sample_rate_hz}, {"progress", progress}};
  } else {
    j["campaign"] = nullptr;
  }
  return j;
}

std::string live_json(const std::string& rig, domain::RigKind kind, const LiveBatch& b) {
  json columns = json::array({"t", "mono_s"});
  for (const char* name : domain::live_signals(kind)) columns.push_back(name);
  json rows = json::array();
  for (const control::LiveSample& s : b.samples) rows.push_back(json::array({s.t, s.mono_s, s.v[0], s.v[1], s.v[2]}));
  const std::uint32_t status = b.samples.empty() ? 0U : b.samples.back().status;
  return json{{"rig", rig}, {"seq", b.seq}, {"run", b.run}, {"first", b.first}, {"lost", b.lost}, {"status", status}, {"columns", columns}, {"samples", rows}}
      .dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string event_json(const EventRow& e) {
  json j{{"id", e.id}, {"campaign", e.campaign}, {"at", e.at}, {"kind", e.kind}};
  j["run"] = e.run != 0 ? json(e.run) : json(nullptr);
  j["t"] = e.has_t ? json(e.t) : json(nullptr);
  if (!e.rig.empty()) j["rig"] = e.rig;
  if (e.kind == "state") j["from"] = e.from_state, j["to"] = e.to_state;
  // The detail as stored: a JSON document for most kinds, a sentence for some: both kept.
  json detail = json::parse(e.detail, nullptr, false);
  j["detail"] = detail.is_discarded() ? json(e.detail) : detail;
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string status_json(const LabConfig& lab, const std::string& state, const std::string& started_at, const std::string& reason,
                        const std::vector<std::string>& rigs) {
  json j{{"state", state}, {"lab", lab.name}, {"daemon", lab.daemon}, {"version", HYSTLAB_VERSION}, {"started_at", started_at}, {"rigs", rigs}};
  if (!reason.empty()) j["reason"] = reason;
  if (!lab.url.empty()) j["url"] = lab.url;  // where the lab view links to this daemon's own page
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace hystlab::lab::detail
