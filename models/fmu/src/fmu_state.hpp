#pragma once
// A serialized FMU state (fmi2SerializeFMUstate): pure encode/decode, fuzzed (tests/fuzz).
// Bytes: "HYSTLAB-FMU-STATE" and a NUL, a version (u32), the GUID of the FMU that wrote it (u32
// length, bytes), then the numbers (u32 count, IEEE doubles), all little-endian. The numbers are
// the instance's time, input, input derivatives and parameters, then the model's own state.
#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace hystlab::fmu {

struct StateRecord {
  std::string guid;
  std::vector<double> numbers;
};

[[nodiscard]] std::vector<char> encode_state(const StateRecord& r);
// Throws std::invalid_argument naming what is wrong (not a state, another version, truncated).
[[nodiscard]] StateRecord decode_state(std::span<const char> bytes);

}  // namespace hystlab::fmu
