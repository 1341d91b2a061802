#pragma once
// Numbers and times as hystlab writes them in text, named once for every export and front end.
// Pure: the time is the caller's.
#include <charconv>
#include <ctime>
#include <string>

namespace hystlab::models {

// The shortest text that reads back to the same double: what was measured or identified is what
// the other tool gets, and 2.95 stays 2.95.
inline void append_exact(std::string& out, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

[[nodiscard]] inline std::string exact_text(double v) {
  std::string s;
  append_exact(s, v);
  return s;
}

// ISO 8601 in UTC to the second ("2026-11-25T10:57:27Z"), as provenance and files record it.
[[nodiscard]] inline std::string iso8601_utc(std::time_t t) {
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace hystlab::models
