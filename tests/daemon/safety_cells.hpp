#pragma once
// The safety matrix's vocabulary and its cells (safety_cells.cpp): the states a rig and its
// campaign can be in, the events that must stop, hold or change them, and what one cell found.
#include <array>
#include <string>
#include <utility>
#include <vector>

namespace hystlab::test {

enum class State {
  idle,
  queued,
  arming_ready,
  arming_enable,
  preamble,
  training,
  ramping,
  dwelling,
  retake,
  validation,
  paused,
  safing,
  shaker_check,
  shaker_control,
  shaker_measure,
  shaker_ramp,
  shaker_sweep,
  shaker_dwell,
  shaker_change,
  finishing,
  held_after_restart,
  limit_recovery
};
enum class Event {
  rig_estop,
  campaign_estop,
  abort,
  pause,
  resume,
  reset,
  ctl_estop,
  ctl_fault,
  limit_trip,
  not_ready,
  enable_dropped,
  link_lost,
  stale_counter,
  heartbeat_lost,
  dead_band,
  strategy_exception,
  db_busy,
  db_failing,
  ring_full,
  finisher_failing
};
inline constexpr std::array kStates{
    State::idle,           State::queued,      State::arming_ready, State::arming_enable, State::preamble,      State::training,     State::ramping,
    State::dwelling,       State::retake,      State::validation,   State::paused,        State::safing,        State::shaker_check, State::shaker_control,
    State::shaker_measure, State::shaker_ramp, State::shaker_sweep, State::shaker_dwell,  State::shaker_change, State::finishing,    State::held_after_restart,
    State::limit_recovery};
inline constexpr std::array kEvents{
    Event::rig_estop, Event::campaign_estop,     Event::abort,     Event::pause,          Event::resume,    Event::reset,           Event::ctl_estop,
    Event::ctl_fault, Event::limit_trip,         Event::not_ready, Event::enable_dropped, Event::link_lost, Event::stale_counter,   Event::heartbeat_lost,
    Event::dead_band, Event::strategy_exception, Event::db_busy,   Event::db_failing,     Event::ring_full, Event::finisher_failing};
[[nodiscard]] const char* to_string(State s) noexcept;
[[nodiscard]] const char* to_string(Event e) noexcept;

struct CellResult {
  std::string state, event;
  bool applies = true;
  std::string why_not;                  // when it does not apply
  std::string outcome;                  // the campaign's end and reason, the rig's state after
  std::string bound;                    // measured: periods from the event to the rig's first safe write
  std::vector<std::string> violations;  // each a failed assertion, said in words
};

// One cell: the state reached on the fake rig, the event injected there, everything asserted.
[[nodiscard]] CellResult run_cell(State s, Event e);
// A whole campaign (a FOT on a load frame, or a sweep on a shaker) with events at the given rig
// times from its start; the invariants and each stop's bound asserted.
[[nodiscard]] CellResult run_schedule(bool shaker, const std::vector<std::pair<double, Event>>& schedule);
// The matrix as docs/SAFETY.md shows it.
[[nodiscard]] std::string matrix_markdown(const std::vector<CellResult>& cells);

}  // namespace hystlab::test
