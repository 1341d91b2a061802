#pragma once
// GET /api/stream: Server-Sent Events. Samples from the rigs' live rings, decimated to the rate
// the client asks (?rate=Hz, no id: they are re-readable from /api/runs/ID/samples), and the
// stored records as they land: campaign state changes and other events, FOT nodes, tables,
// transmissibility points. Record events carry the id "E.N.T" (the last events, fot_nodes and
// tables row sent); a client that reconnects with Last-Event-ID gets every record after it, from
// the database, so nothing is missed across reconnects or daemon restarts.
#include <httplib.h>

#include <optional>
#include <string>

#include "api_support.hpp"

namespace hystlab::web {

struct StreamCursor {
  std::int64_t event = 0, node = 0, table = 0;
  [[nodiscard]] std::string id() const;
};
// "E.N.T" with three non-negative integers; nullopt otherwise.
[[nodiscard]] std::optional<StreamCursor> parse_cursor(const std::string& text);

void add_stream_route(httplib::Server& s, ApiContext& c);

}  // namespace hystlab::web
