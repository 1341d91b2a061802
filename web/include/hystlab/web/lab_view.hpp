#pragma once
// The lab view (docs/LAB.md, "One view of the lab"): hystlabd with a lab section and no rigs
// serves a read-only page over the whole lab: every daemon and rig with its live state (from the
// broker, through lab::LabWatch), every campaign and table (from the lab's PostgreSQL), a
// campaign's plots, and a link to each rig's own daemon for commands. It moves nothing: every
// request other than GET is refused.
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>

#include "hystlab/control/http_config.hpp"
#include "hystlab/lab/lab_config.hpp"

namespace hystlab::web {

class LabView {
 public:
  // live: lab::LabWatch::snapshot() (daemons' status and rigs' state from MQTT), from the HTTP
  // threads. Binds http.bind:http.port (0: a free one); throws std::runtime_error when it cannot.
  using LiveSource = std::function<nlohmann::json()>;
  LabView(const control::HttpConfig& http, const lab::LabConfig& lab, LiveSource live);
  ~LabView();
  LabView(const LabView&) = delete;
  LabView& operator=(const LabView&) = delete;
  [[nodiscard]] int port() const noexcept;
  void stop();
  struct Impl;  // lab_view.cpp's, named here so that its route functions can take it

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace hystlab::web
