#pragma once
// The lab view's eyes on the broker (docs/LAB.md, "One view of the lab"): subscribes to every
// daemon's status and every rig's state of one lab (hystlab/<lab>/+/status, .../+/+/state, both
// retained, so a view started later sees them at once) and keeps the newest of each. Read-only:
// what arrives is shown, never acted on. A broker down is a status with its reason and a
// retry with back-off, as the publisher's.
//
// Thread rule: start/stop from the owner's thread; snapshot() from any thread.
#include <memory>
#include <nlohmann/json.hpp>

#include "hystlab/lab/lab_config.hpp"

namespace hystlab::lab {

class LabWatch {
 public:
  explicit LabWatch(const LabConfig& config);
  ~LabWatch();  // stop()
  LabWatch(const LabWatch&) = delete;
  LabWatch& operator=(const LabWatch&) = delete;
  void start();
  void stop() noexcept;
  // {"connected": bool, "error": text|null, "daemons": {name: status document + "received_at"},
  //  "rigs": {daemon: {rig: state document + "received_at"}}}
  [[nodiscard]] nlohmann::json snapshot() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A topic level back to the name it escapes (%XX, as topic_level writes it).
[[nodiscard]] std::string level_name(const std::string& level);

}  // namespace hystlab::lab
