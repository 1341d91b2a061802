#pragma once
// What the MQTT publisher reads from the daemon's SQLite file: new rows of the events table (by
// id, as the HTTP event stream reads them) and a FOT campaign's node count (its progress). A
// connection of its own, opened on first use and again after an error.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hystlab/db/sqlite.hpp"
#include "mqtt_payloads.hpp"

namespace hystlab::lab::detail {

class RecordReader {
 public:
  explicit RecordReader(std::string path) : path_(std::move(path)) {}
  // The newest event's id (0: none yet): the publisher starts after it.
  [[nodiscard]] std::int64_t newest_event();
  // Events after id, oldest first, at most limit, each with its campaign's rig's name.
  [[nodiscard]] std::vector<EventRow> events_after(std::int64_t id, int limit);
  // Nodes identified so far by a FOT campaign; -1 for another kind (or an unknown campaign).
  [[nodiscard]] std::int64_t fot_nodes(std::int64_t campaign);
  // Drops the connection (after an error): the next call opens it again.
  void reset() noexcept { db_.reset(); }

 private:
  db::Database& db();
  std::string path_;
  std::unique_ptr<db::Database> db_;
};

}  // namespace hystlab::lab::detail
