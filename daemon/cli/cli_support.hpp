#pragma once
// Shared plumbing of the hystlab CLI: options, files, CSV. Every user error is a CliError,
// printed as one line by main() with exit code 2.
#include <algorithm>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "hystlab/db/store.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/hysteresis_model.hpp"

namespace hystlab::cli {

struct CliError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Parses "--name value", "--name=value", flags and "-o value". Unknown options are errors.
class Options {
 public:
  Options(const std::vector<std::string>& args, const std::set<std::string>& with_value, const std::set<std::string>& flags);
  [[nodiscard]] bool has(const std::string& name) const { return values_.count(name) > 0; }
  [[nodiscard]] std::string get(const std::string& name, const std::string& fallback = "") const;
  [[nodiscard]] std::string require(const std::string& name) const;
  [[nodiscard]] double number(const std::string& name, double fallback) const;
  [[nodiscard]] int integer(const std::string& name, int fallback, int lo, int hi) const;
  // "a,b,c": numbers separated by commas; empty when the option is absent.
  [[nodiscard]] std::vector<double> numbers(const std::string& name) const;
  // "a,b" with a < b.
  [[nodiscard]] std::pair<double, double> range(const std::string& name) const;

 private:
  std::map<std::string, std::string> values_;
};

[[nodiscard]] std::string read_file(const std::string& path);

// Every JSON file the user names (a table, parameters, a plan) is read here. what: "table file",
// "parameter file", "plan file". A file that is not JSON is one CliError naming the file, the
// place and the fault: "table file 'x.txt' is not JSON: line 1, column 1: unexpected 'h'".
struct JsonFile {
  std::string text;  // as read: the documents' numbers are parsed from it, not from a re-dump
  nlohmann::json json;
};
[[nodiscard]] JsonFile read_json_file(const std::string& path, const std::string& what);
// A table or parameter document from its file: JSON as above, then the document's own checks,
// named by the file ("table file 'T.json': unknown format version 7").
[[nodiscard]] models::TableDocument read_table_file(const std::string& path);
[[nodiscard]] models::SmaParameters read_params_file(const std::string& path);
// --db must name hystlabd's database: a CliError when no such file (a mistyped path would
// otherwise create an empty database).
void require_database(const std::string& path);
// The daemon's database named by --db (default hystlab.db): it must exist (a mistyped --db would
// otherwise create an empty one).
[[nodiscard]] db::Store open_store(const Options& opt);
void write_file(const std::string& path, const std::string& text);
// Writes to the file, or to stdout when path is empty or "-".
void write_output(const std::string& path, const std::string& text);

class Csv {
 public:
  static Csv load(const std::string& path);
  static Csv parse(const std::string& text, const std::string& name);
  // The named column as finite numbers; errors name the file, line and column.
  [[nodiscard]] std::vector<double> column(const std::string& name) const;
  [[nodiscard]] bool has_column(const std::string& name) const { return std::find(header_.begin(), header_.end(), name) != header_.end(); }
  [[nodiscard]] std::size_t rows() const { return rows_.size(); }
  [[nodiscard]] std::size_t line_of(std::size_t row) const { return lines_[row]; }

 private:
  std::string name_;
  std::vector<std::string> header_;
  std::vector<std::vector<std::string>> rows_;
  std::vector<std::size_t> lines_;
};

[[nodiscard]] std::string format_number(double v);
[[nodiscard]] std::string to_csv(const std::vector<std::string>& header, const std::vector<std::vector<double>>& cols);
[[nodiscard]] std::string now_iso8601();
// A stored time ("2026-11-26T04:41:08.123Z", as hystlabd writes them) with its zone, for people:
// "2026-11-26 04:41:08 UTC"; a text of another form is returned as it is.
[[nodiscard]] std::string utc_time(const std::string& iso);

// A table for the terminal: each column as wide as its widest cell (counted in characters, not
// UTF-8 bytes), two spaces apart, numbers (right) ending at the same place; no trailing blanks.
struct Column {
  std::string title;
  bool right = false;
};
[[nodiscard]] std::string aligned_table(const std::vector<Column>& columns, const std::vector<std::vector<std::string>>& rows);

// --model simplified [--params P.json] or --table T.json
struct LoadedModel {
  std::unique_ptr<models::HysteresisModel> model;
  std::string description;
  double lo = 0.0, hi = 0.0;  // range of a table model (lo == hi: unbounded)
};
[[nodiscard]] LoadedModel load_model(const Options& opt);

}  // namespace hystlab::cli
