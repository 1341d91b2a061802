#include "hystlab/models/document_source.hpp"

#include <algorithm>
#include <cstdio>

namespace hystlab::models {
namespace {
// The byte the parser stopped at, for people: 'h', a line break, byte 0xC3.
std::string byte_named(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (c == '\n' || c == '\r') return "line break";
  if (c == '\t') return "tab";
  if (u < 0x20 || u >= 0x7f) {
    char b[16];
    std::snprintf(b, sizeof b, "byte 0x%02X", u);
    return b;
  }
  return std::string("'") + c + "'";
}

// A document's own fault, named by its source: "table: missing field 'rows'" -> "table file
// 'T.json': missing field 'rows'".
FormatError named(const std::string& source, const std::string& prefix, const FormatError& e) {
  std::string msg = e.what();
  if (msg.rfind(prefix, 0) == 0) msg = msg.substr(prefix.size());
  return FormatError(source + ": " + msg);
}
}  // namespace

std::string json_fault(std::string_view text, const nlohmann::json::exception& e) {
  const auto* pe = dynamic_cast<const nlohmann::json::parse_error*>(&e);
  if (pe == nullptr) return e.what();
  const std::size_t at = std::min<std::size_t>(pe->byte > 0 ? pe->byte - 1 : 0, text.size());  // text.size(): its end
  std::size_t line = 1, column = 1;
  for (std::size_t k = 0; k < at; ++k) {
    if (text[k] == '\n')
      ++line, column = 1;
    else if ((static_cast<unsigned char>(text[k]) & 0xC0) != 0x80)
      ++column;  // characters, not UTF-8 bytes
  }
  const bool blank = text.find_first_not_of(" \t\r\n") == std::string_view::npos;
  std::string what = at >= text.size() ? (blank ? "the file is empty" : "the file ends too early") : "unexpected " + byte_named(text[at]);
  const std::string msg = e.what();
  if (const auto x = msg.rfind("; expected "); x != std::string::npos && !blank) {
    const std::string expected = msg.substr(x + 11);
    what += expected.find("or a literal") != std::string::npos ? ", expected a value"
            : expected == "end of input"                       ? " after the end of the document"
                                                               : ", expected " + expected;
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column) + ": " + what;
}

nlohmann::json parse_document(std::string_view text, const std::string& source) {
  try {
    return nlohmann::json::parse(text.begin(), text.end());
  } catch (const nlohmann::json::exception& e) {
    throw FormatError(source + " is not JSON: " + json_fault(text, e));
  }
}

TableDocument table_from_source(std::string_view text, const std::string& source) {
  (void)parse_document(text, source);  // not JSON: said with the place
  try {
    return table_from_json(text);
  } catch (const FormatError& e) {
    throw named(source, "table: ", e);
  }
}

SmaParameters params_from_source(std::string_view text, const std::string& source) {
  (void)parse_document(text, source);
  try {
    return params_from_json(text);
  } catch (const FormatError& e) {
    throw named(source, "parameters: ", e);
  }
}

}  // namespace hystlab::models
