#include "cli_support.hpp"
#include <filesystem>
#include "hystlab/models/document_source.hpp"
#include "hystlab/models/text_forms.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <iostream>
#include <sstream>

#include "hystlab/models/formats.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/simplified_sma.hpp"

namespace hystlab::cli {

Options::Options(const std::vector<std::string>& args, const std::set<std::string>& with_value, const std::set<std::string>& flags) {
  for (std::size_t k = 0; k < args.size(); ++k) {
    std::string a = args[k];
    if (a == "-o") a = "--output";
    if (a.rfind("--", 0) != 0) throw CliError("unexpected argument '" + a + "' (see --help)");
    std::string name = a.substr(2), value;
    const auto eq = name.find('=');
    const bool inline_value = eq != std::string::npos;
    if (inline_value) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
    }
    if (flags.count(name)) {
      if (inline_value) throw CliError("option --" + name + " takes no value");
      values_[name] = "1";
    } else if (with_value.count(name)) {
      if (!inline_value) {
        if (k + 1 >= args.size()) throw CliError("option --" + name + " needs a value");
        value = args[++k];
      }
      values_[name] = value;
    } else {
      throw CliError("unknown option --" + name + " (see --help)");
    }
  }
}

std::string Options::get(const std::string& name, const std::string& fallback) const {
  const auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

std::string Options::require(const std::string& name) const {
  const auto it = values_.find(name);
  if (it == values_.end() || it->second.empty()) throw CliError("missing required option --" + name);
  return it->second;
}

namespace {
double parse_double(const std::string& s, const std::string& what) {
  const char* b = s.data();
  const char* e = b + s.size();
  while (b < e && (*b == ' ' || *b == '\t')) ++b;
  while (e > b && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '\r')) --e;
  if (b < e && *b == '+') ++b;
  double v = 0.0;
  const auto r = std::from_chars(b, e, v);
  if (b == e || r.ec != std::errc() || r.ptr != e) throw CliError(what + ": '" + s + "' is not a number");
  if (!std::isfinite(v)) throw CliError(what + ": '" + s + "' is not a finite number");
  return v;
}
}  // namespace

double Options::number(const std::string& name, double fallback) const { return has(name) ? parse_double(get(name), "option --" + name) : fallback; }

int Options::integer(const std::string& name, int fallback, int lo, int hi) const {
  if (!has(name)) return fallback;
  const double v = number(name, 0.0);
  if (v != std::floor(v) || v < lo || v > hi)
    throw CliError("option --" + name + ": must be a whole number from " + std::to_string(lo) + " to " + std::to_string(hi) + ", got '" + get(name) + "'");
  return static_cast<int>(v);
}

std::vector<double> Options::numbers(const std::string& name) const {
  std::vector<double> out;
  if (!has(name)) return out;
  const std::string s = get(name);
  std::size_t start = 0;
  while (start <= s.size()) {
    const std::size_t comma = std::min(s.find(',', start), s.size());
    out.push_back(parse_double(s.substr(start, comma - start), "option --" + name));
    start = comma + 1;
  }
  return out;
}

std::pair<double, double> Options::range(const std::string& name) const {
  const std::string s = require(name);
  const auto comma = s.find(',');
  if (comma == std::string::npos) throw CliError("option --" + name + ": expected 'start,end', got '" + s + "'");
  const double a = parse_double(s.substr(0, comma), "option --" + name);
  const double b = parse_double(s.substr(comma + 1), "option --" + name);
  if (!(b > a)) throw CliError("option --" + name + ": the end must be greater than the start, got '" + s + "'");
  return {a, b};
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CliError("cannot open '" + path + "': " + std::strerror(errno));
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw CliError("cannot read '" + path + "'");
  return s.str();
}

JsonFile read_json_file(const std::string& path, const std::string& what) {
  JsonFile f;
  f.text = read_file(path);
  try {
    f.json = models::parse_document(f.text, models::file_source(what, path));
  } catch (const models::FormatError& e) {
    throw CliError(e.what());
  }
  return f;
}

// (models/document_source.hpp names the file in the document's own errors too.)
models::TableDocument read_table_file(const std::string& path) {
  try {
    return models::table_from_source(read_file(path), models::file_source("table file", path));
  } catch (const models::FormatError& e) {
    throw CliError(e.what());
  }
}

models::SmaParameters read_params_file(const std::string& path) {
  try {
    return models::params_from_source(read_file(path), models::file_source("parameter file", path));
  } catch (const models::FormatError& e) {
    throw CliError(e.what());
  }
}

void write_file(const std::string& path, const std::string& text) {
  // Write beside the target and rename, so a failure never leaves half a file.
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw CliError("cannot write '" + path + "': " + std::strerror(errno));
    out << text;
    out.flush();
    if (!out) throw CliError("cannot write '" + path + "'");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw CliError("cannot write '" + path + "': " + std::strerror(errno));
  }
}

void write_output(const std::string& path, const std::string& text) {
  if (path.empty() || path == "-")
    std::cout << text << std::flush;
  else
    write_file(path, text);
}

namespace {
std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur += c;
    }
  }
  out.push_back(cur);
  for (std::string& f : out) {  // trim blanks and one pair of quotes
    const auto b = f.find_first_not_of(" \t"), e = f.find_last_not_of(" \t");
    f = b == std::string::npos ? std::string() : f.substr(b, e - b + 1);
    if (f.size() >= 2 && f.front() == '"' && f.back() == '"') f = f.substr(1, f.size() - 2);
  }
  return out;
}
}  // namespace

Csv Csv::load(const std::string& path) { return parse(read_file(path), path); }

Csv Csv::parse(const std::string& text, const std::string& name) {
  Csv csv;
  csv.name_ = name;
  std::istringstream in(text);
  std::string line;
  std::size_t lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (csv.header_.empty()) {
      csv.header_ = split_fields(line);
      continue;
    }
    auto fields = split_fields(line);
    if (fields.size() != csv.header_.size())
      throw CliError(name + ": line " + std::to_string(lineno) + ": has " + std::to_string(fields.size()) + " fields, the header has " +
                     std::to_string(csv.header_.size()));
    csv.rows_.push_back(std::move(fields));
    csv.lines_.push_back(lineno);
  }
  if (csv.header_.empty()) throw CliError(name + ": empty file (expected a header row)");
  if (csv.rows_.empty()) throw CliError(name + ": no data rows below the header");
  return csv;
}

std::vector<double> Csv::column(const std::string& col) const {
  std::size_t idx = header_.size();
  for (std::size_t k = 0; k < header_.size(); ++k)
    if (header_[k] == col) idx = k;
  if (idx == header_.size()) {
    std::string have;
    for (const auto& h : header_) have += (have.empty() ? "" : ", ") + h;
    throw CliError(name_ + ": no column '" + col + "' (the header has: " + have + ")");
  }
  std::vector<double> out;
  out.reserve(rows_.size());
  for (std::size_t r = 0; r < rows_.size(); ++r)
    out.push_back(parse_double(rows_[r][idx], name_ + ": line " + std::to_string(lines_[r]) + ", column '" + col + "'"));
  return out;
}

std::string format_number(double v) { return models::exact_text(v); }

std::string to_csv(const std::vector<std::string>& header, const std::vector<std::vector<double>>& cols) {
  std::string out;
  for (std::size_t c = 0; c < header.size(); ++c) out += (c ? "," : "") + header[c];
  out += '\n';
  const std::size_t n = cols.empty() ? 0 : cols.front().size();
  for (std::size_t r = 0; r < n; ++r) {
    for (std::size_t c = 0; c < cols.size(); ++c) {
      if (c) out += ',';
      out += format_number(cols[c][r]);
    }
    out += '\n';
  }
  return out;
}

std::string now_iso8601() { return models::iso8601_utc(std::time(nullptr)); }

std::string utc_time(const std::string& iso) {
  // YYYY-MM-DDTHH:MM:SS[.fff]Z
  const bool ok = iso.size() >= 20 && iso[4] == '-' && iso[7] == '-' && iso[10] == 'T' && iso[13] == ':' && iso[16] == ':' && iso.back() == 'Z';
  return ok ? iso.substr(0, 10) + " " + iso.substr(11, 8) + " UTC" : iso;
}

namespace {
std::size_t characters(const std::string& s) {
  std::size_t n = 0;
  for (const char c : s) n += (static_cast<unsigned char>(c) & 0xC0) != 0x80 ? 1 : 0;
  return n;
}
}  // namespace

std::string aligned_table(const std::vector<Column>& columns, const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> width(columns.size());
  for (std::size_t c = 0; c < columns.size(); ++c) width[c] = characters(columns[c].title);
  for (const auto& r : rows)
    for (std::size_t c = 0; c < columns.size() && c < r.size(); ++c) width[c] = std::max(width[c], characters(r[c]));
  std::string out;
  const auto line = [&](const auto& cell) {
    std::string l;
    for (std::size_t c = 0; c < columns.size(); ++c) {
      const std::string& text = cell(c);
      const std::string pad(width[c] - characters(text), ' ');
      l += (c ? "  " : "") + (columns[c].right ? pad + text : text + pad);
    }
    out += l.substr(0, l.find_last_not_of(' ') + 1) + "\n";
  };
  line([&](std::size_t c) -> const std::string& { return columns[c].title; });
  static const std::string none;
  for (const auto& r : rows) line([&](std::size_t c) -> const std::string& { return c < r.size() ? r[c] : none; });
  return out;
}

namespace {
// Where the simplified model with p's parameters is defined, in words: from above Af0 (austenite
// at rest) to where a transformation line becomes as steep as an elastic one (found by bisection:
// every condition of validate() is linear in T).
std::string superelastic_range(models::SmaParameters p) {
  auto ok = [&p](double T) {
    p.T = T;
    try {
      models::validate(p);
      return true;
    } catch (const std::invalid_argument&) {
      return false;
    }
  };
  double lo = p.Af0 + 1e-6, hi = p.Af0 + 1000;
  if (!ok(lo)) return "the simplified model with these parameters is not superelastic at any temperature";
  if (ok(hi)) return "the simplified model with these parameters holds above Af0 = " + format_number(p.Af0) + " °C";
  for (int k = 0; k < 60; ++k) (ok(0.5 * (lo + hi)) ? lo : hi) = 0.5 * (lo + hi);
  char b[128];
  std::snprintf(b, sizeof b, "the simplified model with these parameters holds from Af0 = %g °C to %.1f °C", p.Af0, lo);
  return b;
}
}  // namespace

LoadedModel load_model(const Options& opt) {
  LoadedModel m;
  if (opt.has("table")) {
    if (opt.has("model")) throw CliError("give either --table or --model, not both");
    const std::string path = opt.require("table");
    auto doc = read_table_file(path);
    m.lo = doc.table.grid().lo;
    m.hi = doc.table.grid().hi;
    m.description = "Everett table " + path + " (n = " + std::to_string(doc.table.grid().n) + ")";
    m.model = std::make_unique<models::PreisachModel>(std::move(doc.table));
    return m;
  }
  const std::string kind = opt.get("model");
  if (kind.empty()) throw CliError("missing --table T.json or --model simplified");
  if (kind != "simplified") throw CliError("unknown model '" + kind + "' (known: simplified)");
  models::SmaParameters p = models::table1_parameters();
  m.description = "simplified SMA model, Table 1 parameters (built in)";
  if (opt.has("params")) {
    const std::string path = opt.require("params");
    p = read_params_file(path);
    m.description = "simplified SMA model, parameters " + path;
  }
  if (opt.has("temperature")) {  // hystlab eval --temperature: the specimen at another temperature
    p.T = opt.number("temperature", p.T);
    m.description += " at " + format_number(p.T) + " °C";
    try {
      models::validate(p);
    } catch (const std::invalid_argument& e) {
      throw CliError("--temperature " + format_number(p.T) + ": " + superelastic_range(p) + " (" + e.what() + ")");
    }
  }
  m.model = std::make_unique<models::SimplifiedSmaModel>(p);
  return m;
}

db::Store open_store(const Options& opt) {
  const std::string path = opt.get("db", "hystlab.db");
  require_database(path);
  return db::Store(path);
}

void require_database(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw CliError("--db: no database at '" + path + "' (hystlabd creates it; give the path it uses)");
}

}  // namespace hystlab::cli
