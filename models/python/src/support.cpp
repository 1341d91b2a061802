#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>

#include "bindings.hpp"
#include "hystlab/models/document_source.hpp"
#include "hystlab/models/fingerprint.hpp"
#include "hystlab/models/text_forms.hpp"

namespace hystlab::python {

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw FileError("cannot open '" + path.string() + "': " + std::strerror(err), err);
  }
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad() || s.fail()) throw FileError("cannot read '" + path.string() + "'", errno ? errno : EIO);
  return s.str();
}

void write_file(const fs::path& path, const std::string& text) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      const int err = errno;
      throw FileError("cannot write '" + path.string() + "': " + std::strerror(err), err);
    }
    out << text;
    out.flush();
    if (!out) throw FileError("cannot write '" + path.string() + "'", errno ? errno : EIO);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    throw FileError("cannot write '" + path.string() + "': " + std::strerror(err), err);
  }
}

std::string format_number(double v) { return models::exact_text(v); }

std::string now_iso8601() { return models::iso8601_utc(std::time(nullptr)); }

py::object json_to_py(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

nlohmann::json py_to_json(const py::handle& obj) {
  const std::string text = py::str(py::module_::import("json").attr("dumps")(obj, py::arg("allow_nan") = false));
  return nlohmann::json::parse(text);
}

std::vector<double> finite_vector(const py::handle& obj, const char* name) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  if (!a) throw std::invalid_argument(std::string(name) + ": expected an array of numbers");
  const double* p = a.data();
  const auto n = static_cast<std::size_t>(a.size());
  for (std::size_t k = 0; k < n; ++k)
    if (!std::isfinite(p[k])) throw std::invalid_argument(std::string(name) + "[" + std::to_string(k) + "] is not a finite number");
  return std::vector<double>(p, p + n);
}

py::array_t<double> to_numpy(std::span<const double> v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

namespace {
struct Fnv {  // the bytes of the values, chained through models::fnv1a64
  std::uint64_t h = models::kFnvBasis;
  void add(const void* data, std::size_t n) { h = models::fnv1a64({static_cast<const char*>(data), n}, h); }
  void add(double v) { add(&v, sizeof v); }
};
}  // namespace

std::uint64_t fingerprint(const models::EverettTable& t) {
  Fnv f;
  f.add("preisach", 8);
  const models::Grid& g = t.grid();
  for (int i = 0; i <= g.n; ++i) f.add(g.node(i));
  for (double v : t.values()) f.add(v);
  f.add(t.force_offset());
  return f.h;
}

std::uint64_t fingerprint(const models::SmaParameters& p) {
  Fnv f;
  f.add("simplified-sma", 14);
  for (double v : {p.KA, p.KM, p.dtr_max, p.C, p.Mf0, p.Ms0, p.As0, p.Af0, p.T}) f.add(v);
  return f.h;
}

Table make_table(models::EverettTable table, models::TableProvenance provenance) {
  return Table{std::make_shared<models::TableDocument>(models::TableDocument{std::move(table), std::move(provenance)})};
}

Table table_from_text(std::string_view text, const std::string& source) {
  return Table{std::make_shared<models::TableDocument>(models::table_from_source(text, source))};
}
Table table_from_file(const fs::path& path) { return table_from_text(read_file(path), models::file_source("table file", path.string())); }
Params params_from_file(const fs::path& path) { return params_from_text(read_file(path), models::file_source("parameter file", path.string())); }

std::string table_text(const Table& t) { return models::table_to_json(t.table(), t.doc->provenance).dump(2) + "\n"; }

Params params_from_text(std::string_view text, const std::string& source) {
  Params out{models::params_from_source(text, source), {}};
  // params_from_json validated the document; the source is kept for the next save.
  const auto j = nlohmann::json::parse(text.begin(), text.end());
  if (const auto s = j.find("source"); s != j.end() && s->is_string()) out.source = s->get<std::string>();
  return out;
}

std::string params_text(const Params& p) { return models::params_to_json(p.p, p.source).dump(2) + "\n"; }

}  // namespace hystlab::python
