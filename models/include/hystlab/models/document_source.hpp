#pragma once
// A table or parameter document read from where the user keeps it (a file, or text handed over
// in Python), with one error that names it: "table file 'x.txt' is not JSON: line 1, column 1:
// unexpected 'h'", "table file 'T.json': unknown format version 7", "table text: missing field
// 'rows'". The CLI and the Python module both read documents here, so they say the same thing.
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "hystlab/models/formats.hpp"

namespace hystlab::models {

// "line 3, column 4: unexpected ',', expected a value" from the parser's error on text.
[[nodiscard]] std::string json_fault(std::string_view text, const nlohmann::json::exception& e);

// text parsed as JSON; FormatError("<source> is not JSON: <fault>") otherwise. source: what the
// user calls it ("plan file 'P.json'").
[[nodiscard]] nlohmann::json parse_document(std::string_view text, const std::string& source);

// The document's own checks after that, its errors named by source instead of the kind's prefix.
[[nodiscard]] TableDocument table_from_source(std::string_view text, const std::string& source);
[[nodiscard]] SmaParameters params_from_source(std::string_view text, const std::string& source);

// How a file is named in those errors: "table file 'T.json'".
[[nodiscard]] inline std::string file_source(const std::string& what, const std::string& path) { return what + " '" + path + "'"; }

}  // namespace hystlab::models
