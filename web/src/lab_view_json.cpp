#include "lab_view_json.hpp"

#include <cmath>
#include <set>

namespace hystlab::web {
using nlohmann::json;
namespace {
json text_or_null(const std::string& s) { return s.empty() ? json(nullptr) : json(s); }
json number_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
// A JSON text column as JSON; text that is not JSON as itself (never lost, never a 500).
json parsed(const std::string& s) {
  if (s.empty()) return nullptr;
  json j = json::parse(s, nullptr, false);
  return j.is_discarded() ? json(s) : j;
}
// A text field of a document from the broker (anyone who may publish there wrote it): its text,
// or def when missing or not text. Never throws.
std::string text_of(const json& doc, const char* key, const std::string& def = {}) {
  if (!doc.is_object()) return def;
  const auto it = doc.find(key);
  return it != doc.end() && it->is_string() ? it->get<std::string>() : def;
}
// Only an http(s) address is a link (a javascript: one from the broker never is).
json link_or_null(const std::string& url) { return url.rfind("http://", 0) == 0 || url.rfind("https://", 0) == 0 ? json(url) : json(nullptr); }

json campaign_row(const db::LabCampaign& c) {
  return {{"daemon", c.daemon},
          {"rig", c.rig},
          {"id", c.id},
          {"kind", c.kind},
          {"state", c.state},
          {"specimen", text_or_null(c.specimen)},
          {"created_at", c.created_at},
          {"updated_at", c.updated_at}};
}
json table_row(const db::LabTable& t) {
  return {{"daemon", t.daemon},
          {"id", t.id},
          {"campaign", t.campaign == 0 ? json(nullptr) : json(t.campaign)},
          {"specimen", text_or_null(t.specimen)},
          {"method", t.method},
          {"n", t.n},
          {"range", {number_or_null(t.range_lo), number_or_null(t.range_hi)}},
          {"created_at", t.created_at},
          {"accuracy", parsed(t.accuracy)}};
}
}  // namespace

json mqtt_status(const json& live) {
  if (!live.is_object() || !live.contains("configured") || live["configured"] != true) return nullptr;
  const auto connected = live.find("connected");
  const std::string error = text_of(live, "error");
  return {{"connected", connected != live.end() && connected->is_boolean() && connected->get<bool>()}, {"error", text_or_null(error)}};
}

json lab_overview_json(const std::string& lab, const std::vector<db::LabDaemon>& daemons, const std::vector<db::LabRig>& rigs, const json& live) {
  const json& seen_daemons = live.is_object() && live.contains("daemons") ? live["daemons"] : json::object();
  const json& seen_rigs = live.is_object() && live.contains("rigs") ? live["rigs"] : json::object();
  json ds = json::array(), rs = json::array();
  std::set<std::string> daemon_names;
  std::set<std::pair<std::string, std::string>> rig_names;
  for (const db::LabDaemon& d : daemons) {
    daemon_names.insert(d.name);
    const json status = seen_daemons.contains(d.name) ? seen_daemons[d.name] : json(nullptr);
    ds.push_back({{"name", d.name},
                  {"software", d.software},
                  {"url", link_or_null(text_of(status, "url", d.url))},
                  {"first_seen", d.first_seen},
                  {"last_seen", d.last_seen},
                  {"online", status.is_object() ? json(text_of(status, "state") == "online") : json(nullptr)},
                  {"status", status}});
  }
  for (const auto& [name, status] : seen_daemons.items())
    if (!daemon_names.contains(name))
      ds.push_back({{"name", name},
                    {"software", text_of(status, "version")},
                    {"url", link_or_null(text_of(status, "url"))},
                    {"first_seen", nullptr},
                    {"last_seen", nullptr},
                    {"online", text_of(status, "state") == "online"},
                    {"status", status}});
  for (const db::LabRig& g : rigs) {
    rig_names.insert({g.daemon, g.name});
    const json state =
        seen_rigs.contains(g.daemon) && seen_rigs[g.daemon].is_object() && seen_rigs[g.daemon].contains(g.name) ? seen_rigs[g.daemon][g.name] : json(nullptr);
    rs.push_back({{"daemon", g.daemon},
                  {"rig", g.name},
                  {"last_campaign", g.last_campaign == 0 ? json(nullptr) : json(g.last_campaign)},
                  {"last_campaign_state", text_or_null(g.last_campaign_state)},
                  {"live", state}});
  }
  for (const auto& [daemon, by_rig] : seen_rigs.items())
    if (by_rig.is_object())
      for (const auto& [rig, state] : by_rig.items())
        if (!rig_names.contains({daemon, rig}))
          rs.push_back({{"daemon", daemon}, {"rig", rig}, {"last_campaign", nullptr}, {"last_campaign_state", nullptr}, {"live", state}});
  return {{"lab", lab}, {"mqtt", mqtt_status(live)}, {"daemons", ds}, {"rigs", rs}};
}

json campaigns_json(const std::vector<db::LabCampaign>& campaigns) {
  json out = json::array();
  for (const db::LabCampaign& c : campaigns) out.push_back(campaign_row(c));
  return out;
}

json campaign_json(const db::LabCampaign& c, const std::vector<db::LabRun>& runs, const std::vector<db::LabEvent>& events,
                   const std::vector<db::LabTable>& tables) {
  json j = campaign_row(c);
  j["plan"] = parsed(c.plan);
  json rs = json::array(), es = json::array(), ts = json::array();
  for (const db::LabRun& r : runs)
    rs.push_back({{"id", r.id},
                  {"role", r.role},
                  {"state", r.state},
                  {"started_at", text_or_null(r.started_at)},
                  {"ended_at", text_or_null(r.ended_at)},
                  {"samples", r.samples},
                  {"signals", r.shaker ? "shaker" : "load_frame"}});
  for (const db::LabEvent& e : events)
    es.push_back(
        {{"id", e.id}, {"at", e.at}, {"kind", e.kind}, {"from", text_or_null(e.from_state)}, {"to", text_or_null(e.to_state)}, {"detail", parsed(e.detail)}});
  for (const db::LabTable& t : tables) ts.push_back(table_row(t));
  j["runs"] = rs;
  j["events"] = es;
  j["tables"] = ts;
  return j;
}

json tables_json(const std::vector<db::LabTable>& tables) {
  json out = json::array();
  for (const db::LabTable& t : tables) out.push_back(table_row(t));
  return out;
}

json overview_json(const db::LabOverview& o) {
  json min = json::object(), max = json::object();
  for (std::size_t c = 0; c < o.columns.size(); ++c) {
    json lo = json::array(), hi = json::array();
    for (const double v : o.min[c]) lo.push_back(number_or_null(v));
    for (const double v : o.max[c]) hi.push_back(number_or_null(v));
    min[o.columns[c]] = lo;
    max[o.columns[c]] = hi;
  }
  return {{"columns", o.columns}, {"buckets", o.min.empty() ? 0 : o.min[0].size()}, {"min", min}, {"max", max}};
}

}  // namespace hystlab::web
