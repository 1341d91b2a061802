#pragma once
// A campaign's events for people (hystlab campaign show): each a sentence built from its detail
// for the kinds hystlabd records (state, command, limits, fit, quality, validation, training,
// shakedown, recommendation, retake, gap(s), safe, record, and a sine campaign's steps, points
// and control), and "key=value, ..." for any other kind: never the stored JSON as it is.
#include <cstddef>
#include <string>

#include "hystlab/db/store.hpp"

namespace hystlab::cli {

// "run 1: 502 samples in 10.14 s of rig time (49.42 Hz; 50 Hz expected), nothing lost"
[[nodiscard]] std::string event_sentence(const db::EventRow& e);

// "04:41:08 UTC  quality  run 1: 502 samples ..." (the time of day: the date is said once above);
// the kind padded to kind_width, so that the sentences of a list start in one column.
[[nodiscard]] std::string event_line(const db::EventRow& e, std::size_t kind_width = 0);

// The detail as "key=value, key=value" (nested keys joined by '.', arrays as [a, b]), or the
// text itself when it is not a JSON object.
[[nodiscard]] std::string detail_pairs(const std::string& detail);

}  // namespace hystlab::cli
