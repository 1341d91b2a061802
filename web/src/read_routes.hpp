#pragma once
// The read endpoints of one daemon's records (docs/API.md): campaigns with their events, nodes,
// loops and runs; runs and their decimated samples and x-y paths; tables with their scores and
// exports; a sweep's points. One set of handlers, two sources (db/reads.hpp): a rig's daemon
// serves them from its own SQLite file at /api/..., the lab view from a daemon's rows in the lab
// database at /daemons/NAME/api/... (web/src/lab_view.cpp), with the same JSON.
#include <httplib.h>

#include <functional>
#include <string>

#include "hystlab/db/reads.hpp"

namespace hystlab::web {

class XYCache;

// What a read handler works on: the source and the cache of runs' x-y columns that goes with it.
struct ReadContext {
  db::ReadSource& store;
  XYCache& xy;
};
using ReadHandler = std::function<void(const httplib::Request&, httplib::Response&, ReadContext&)>;
// Runs the handler on the source that answers this request, or answers the request itself (a
// daemon the lab database does not know: 404; the lab database unreachable: 503).
using WithSource = std::function<void(const httplib::Request&, httplib::Response&, const ReadHandler&)>;

// Registers every read endpoint at prefix + "/api/...". The prefix may hold one capture group
// (the lab view's daemon name): a handler takes its id from the path's last group.
void add_read_routes(httplib::Server& s, const std::string& prefix, WithSource with);

}  // namespace hystlab::web
