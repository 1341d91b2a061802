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
db::RunInfo run_or_404(db::ReadSource& store, std::int64_t id) {
  auto r = store.run(id);
  if (!r) throw ApiError(404, "not found", "no run " + std::to_string(id));
  return *r;
}

std::string table_document(db::ReadSource& store, std::int64_t id) {
  auto doc = store.table_document(id);
  if (!doc) throw ApiError(404, "not found", "no table " + std::to_string(id));
  return *doc;
}

namespace {
// The model named by the body: a stored table, a table document, or simplified-model parameters.
std::unique_ptr<models::HysteresisModel> model_of(const json& body, db::ReadSource& store) {
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
    db::ReadSource& store = reader(db_path);
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

}  // namespace

// A shaker's run (its campaign is a sine sweep).
bool shaker_run(db::ReadSource& store, const db::RunInfo& r) {
  const auto c = store.campaign(r.campaign);
  return c && c->kind == domain::CampaignKind::sine;
}

void add_data_routes(httplib::Server& s, ApiContext& c) {
  s.Get(R"(/api/runs/(\d+)/samples\.csv)", guarded([&c](const httplib::Request& req, httplib::Response& res) {
          auto& store = reader(c.db_path);
          const db::RunInfo r = run_or_404(store, path_id(req));
          // Where its samples are says the rig kind; a run without any, its campaign's kind.
          const db::RunSamples where = db::run_samples(store, r.id);
          stream_csv(res, c.db_path, r.id, where == db::RunSamples::none ? shaker_run(store, r) : where == db::RunSamples::shaker);
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
