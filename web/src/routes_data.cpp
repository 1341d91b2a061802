// Runs and their samples (decimated with min/max per bucket, or full resolution as a streamed
// CSV, db/run_csv.hpp), tables (list, get, export) and model evaluation.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "hystlab/db/run_csv.hpp"
#include "hystlab/fmu/element_export.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/table_export.hpp"
#include "hystlab/models/table_score.hpp"
#include "request_guard.hpp"
#include "routes.hpp"

namespace hystlab::web {
namespace {
db::RunInfo run_or_404(db::Reads& store, std::int64_t id) {
  auto r = store.run(id);
  if (!r) throw ApiError(404, "not found", "no run " + std::to_string(id));
  return *r;
}

std::string table_document(db::Reads& store, std::int64_t id) {
  auto doc = store.table_document(id);
  if (!doc) throw ApiError(404, "not found", "no table " + std::to_string(id));
  return *doc;
}

// The model named by the body: a stored table, a table document, or simplified-model parameters.
std::unique_ptr<models::HysteresisModel> model_of(const json& body, db::Reads& store) {
  const ModelSource source = decode_model_source(body);
  if (source == ModelSource::stored_table) {
    const auto doc = models::table_from_json(table_document(store, body["table_id"].get<std::int64_t>()));
    return std::make_unique<models::PreisachModel>(std::make_shared<const models::EverettTable>(doc.table));
  }
  if (source == ModelSource::table_document) {
    const auto doc = models::table_from_json(body["table"].dump());
    return std::make_unique<models::PreisachModel>(std::make_shared<const models::EverettTable>(doc.table));
  }
  return std::make_unique<models::SimplifiedSmaModel>(models::params_from_json(body["params"].dump()));
}

// Every sample in the one CSV layout of a run (db/run_csv.hpp: the CLI's `runs export` writes the
// same bytes), a window of samples a chunk. A run without samples: its rig kind's header only.
void stream_csv(httplib::Response& res, const std::string& db_path, std::int64_t run, bool shaker) {
  res.set_header("Content-Disposition", "attachment; filename=\"run-" + std::to_string(run) + ".csv\"");
  auto next = std::make_shared<std::int64_t>(-1);  // -1: the header is still to be sent
  res.set_chunked_content_provider("text/csv", [db_path, run, next, shaker](std::size_t, httplib::DataSink& sink) {
    if (*next < 0) {
      const std::string head = db::run_csv_header(shaker);
      *next = 0;
      return sink.write(head.data(), head.size());
    }
    db::Reads& store = reader(db_path);
    std::string chunk;
    const std::int64_t rows = db::append_csv_rows(store, run, shaker, *next, *next + db::kRunCsvWindow - 1, chunk);
    *next += db::kRunCsvWindow;
    if (rows == 0 && *next > db::last_seq(store, run, shaker)) {
      sink.done();
      return true;
    }
    return chunk.empty() || sink.write(chunk.data(), chunk.size());
  });
}

// A shaker's run (its campaign is a sine sweep).
bool shaker_run(db::Reads& store, const db::RunInfo& r) {
  const auto c = store.campaign(r.campaign);
  return c && c->kind == domain::CampaignKind::sine;
}
}  // namespace

void add_data_routes(httplib::Server& s, ApiContext& c) {
  s.Get(R"(/api/runs/(\d+))", guarded([&c](const httplib::Request& req, httplib::Response& res) {
          auto& store = reader(c.db_path);
          const db::RunInfo r = run_or_404(store, path_id(req));
          const auto [t0, t1] = store.time_span(r.id).value_or(std::make_pair(0.0, 0.0));
          send_json(res, {{"id", r.id},
                          {"campaign", r.campaign},
                          {"role", r.role},
                          {"state", r.state},
                          {"started_at", r.started_at},
                          {"ended_at", r.ended_at},
                          {"wall_anchor_unix", r.wall_anchor_unix},
                          {"samples", r.samples},
                          {"t_range_s", {t0, t1}},
                          {"quality", run_quality(store, r.campaign, r.id)}});
        }));
  s.Get(R"(/api/runs/(\d+)/samples)", guarded([&c](const httplib::Request& req, httplib::Response& res) {
          auto& store = reader(c.db_path);
          const db::RunInfo r = run_or_404(store, path_id(req));
          const auto [lo, hi] = store.time_span(r.id).value_or(std::make_pair(0.0, 0.0));
          const double t0 = query_number(req, "t0", lo, -1e12, 1e12), t1 = query_number(req, "t1", hi, -1e12, 1e12);
          if (t1 < t0) throw ApiError(400, "invalid parameter", "t1 must not be before t0");
          const int points = static_cast<int>(query_number(req, "points", 1000, 1, 100000));
          const bool shaker = shaker_run(store, r);
          json t_min, t_max, d_min, d_max, f_min, f_max, n;
          for (const db::Bucket& b : store.overview(r.id, t0, t1, points, shaker)) {
            t_min.push_back(b.t_min), t_max.push_back(b.t_max), d_min.push_back(b.disp_min), d_max.push_back(b.disp_max);
            f_min.push_back(b.force_min), f_max.push_back(b.force_max), n.push_back(b.n);
          }
          // Each bucket's min and max: a shaker's base and mass displacement (its envelope over the
          // bucket), a load frame's displacement and force.
          const std::string a = shaker ? "base_displacement" : "displacement", b = shaker ? "mass_displacement" : "force";
          const std::string bu = shaker ? "_mm" : "_N";
          send_json(res, {{"run", r.id},
                          {"t0", t0},
                          {"t1", t1},
                          {"buckets", n.size()},
                          {"t_min", t_min},
                          {"t_max", t_max},
                          {a + "_min_mm", d_min},
                          {a + "_max_mm", d_max},
                          {b + "_min" + bu, f_min},
                          {b + "_max" + bu, f_max},
                          {"n", n}});
        }));
  s.Get(R"(/api/runs/(\d+)/samples\.csv)", guarded([&c](const httplib::Request& req, httplib::Response& res) {
          auto& store = reader(c.db_path);
          const db::RunInfo r = run_or_404(store, path_id(req));
          // Where its samples are says the rig kind; a run without any, its campaign's kind.
          const db::RunSamples where = db::run_samples(store, r.id);
          stream_csv(res, c.db_path, r.id, where == db::RunSamples::none ? shaker_run(store, r) : where == db::RunSamples::shaker);
        }));
  s.Get("/api/tables", guarded([&c](const httplib::Request&, httplib::Response& res) {
          json out = json::array();
          for (const db::TableInfo& t : reader(c.db_path).tables()) out.push_back(table_json(t));
          send_json(res, out);
        }));
  s.Get(R"(/api/tables/(\d+))", guarded([&c](const httplib::Request& req, httplib::Response& res) {
          auto& store = reader(c.db_path);
          const std::int64_t id = path_id(req);
          const auto t = store.table(id);
          if (!t) throw ApiError(404, "not found", "no table " + std::to_string(id));
          json j = table_json(*t);
          j["document"] = json::parse(table_document(store, id));
          send_json(res, j);
        }));
  // A table scored on any run (a campaign's validation run, typically): the table from its initial
  // state over the run's displacements, against the measured forces, per branch.
  s.Get(R"(/api/tables/(\d+)/score)", guarded([&c](const httplib::Request& req, httplib::Response& res) {
          auto& store = reader(c.db_path);
          const std::int64_t id = path_id(req);
          if (!req.has_param("run")) throw ApiError(400, "invalid parameter", "run: the run to score the table on is required (?run=ID)", "run");
          const std::int64_t run = static_cast<std::int64_t>(query_number(req, "run", 0, 1, 9e15));
          const models::TableDocument doc = models::table_from_json(table_document(store, id));
          const db::RunInfo r = run_or_404(store, run);
          std::vector<double> x, f;
          store.for_each_sample(r.id, 0, std::numeric_limits<std::int64_t>::max(), [&](const db::SampleRow& row) {
            x.push_back(row.disp);
            f.push_back(row.force);
          });
          if (x.size() < 2)
            throw ApiError(409, "conflict", "run " + std::to_string(run) + " has " + std::to_string(x.size()) + " sample(s): nothing to score on");
          json j = models::accuracy_json(models::score_table(doc.table, x, f));
          j["table"] = id;
          j["run"] = r.id;
          j["role"] = r.role;
          send_json(res, j);
        }));
  s.Get(R"(/api/tables/(\d+)/export)", guarded([&c](const httplib::Request& req, httplib::Response& res) {
          const std::int64_t id = path_id(req);
          const std::string format = req.has_param("format") ? req.get_param_value("format") : "json";
          if (!fmu::is_export_format(format)) throw ApiError(400, "invalid parameter", "format: '" + format + "' is not " + std::string(fmu::kExportFormats));
          const std::string text = table_document(reader(c.db_path), id);
          const std::string name = "hystlab_table_" + std::to_string(id);
          res.set_header("Content-Disposition", "attachment; filename=\"" + name + "." + format + "\"");
          if (format == "json") return res.set_content(text, "application/json");  // the stored document as it is
          fmu::ExportedFile f = fmu::export_element(text, format, name);
          res.set_content(std::move(f.bytes), f.media_type);
        }));
  post_route(s, c, "/api/evaluate", guarded([&c](const httplib::Request& req, httplib::Response& res) {
               const json body = body_object(req);
               const auto model = model_of(body, reader(c.db_path));
               const std::vector<double> x = decode_displacements(body);
               std::vector<double> f(x.size());
               for (std::size_t k = 0; k < x.size(); ++k) f[k] = model->step(x[k]);
               send_json(res, {{"force_N", f}, {"samples", f.size()}, {"saturations", model->saturation_count()}});
             }));
}

}  // namespace hystlab::web
