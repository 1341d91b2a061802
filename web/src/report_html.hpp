#pragma once
// A campaign report a lab can file: one self-contained HTML document (inline CSS and SVG, no
// script, nothing fetched), rendered from the stored data only, that prints as it shows
// (Chromium's print to PDF). Pure: the report's document in, HTML out.
//
// The document (report_route.cpp assembles it from the store, as the API serves it):
//   campaign   GET /api/campaigns/ID            software, generated_at   text
//   rig        GET /api/rigs/NAME (or null)     events   GET .../events
//   loops      GET .../loops                    nodes    GET .../nodes (fot)
//   loop       GET /api/runs/RUN/loop (fot, the campaign's run, with the recommended table's model)
//   sweep      GET .../sweep (sine)
#include <nlohmann/json.hpp>
#include <string>

namespace hystlab::web::report {

[[nodiscard]] std::string render_html(const nlohmann::json& doc);

}  // namespace hystlab::web::report
