// libFuzzer: the table and parameter file decoders refuse any text with FormatError, never crash.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "hystlab/models/formats.hpp"
#include "hystlab/models/preisach_model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    hystlab::models::PreisachModel m(hystlab::models::table_from_json(text).table);
    (void)m.step(m.table().grid().hi);  // a table that loads must evaluate
  } catch (const hystlab::models::FormatError&) {
  }
  try {
    (void)hystlab::models::params_from_json(text);
  } catch (const hystlab::models::FormatError&) {
  }
  return 0;
}
