#pragma once
// hystlab._hystlab: the pybind11 binding of hystlab::models (docs/PYTHON.md). The shared pieces:
// the Python-side value types and the plumbing every binding file uses.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "hystlab/models/formats.hpp"
#include "hystlab/models/simplified_sma.hpp"

namespace hystlab::python {

namespace py = pybind11;
namespace fs = std::filesystem;

// A file that cannot be read or written: raised as the OSError subclass of its errno, with the
// CLI's message ("cannot open 'T.json': No such file or directory").
struct FileError : std::runtime_error {
  FileError(const std::string& what, int err) : std::runtime_error(what), code(err) {}
  int code;
};

// hystlab.Table: a table document. Shared, so that models built from it hold the table itself
// (no copy) and a Table stays valid for as long as any model uses it.
struct Table {
  std::shared_ptr<models::TableDocument> doc;
  [[nodiscard]] const models::EverettTable& table() const { return doc->table; }
};

// hystlab.Params: simplified-model parameters, validated, and the document's "source".
struct Params {
  models::SmaParameters p;
  std::string source;
};

// The CLI's file plumbing (daemon/cli/cli_support.cpp), with its messages: the module's errors
// read as the CLI's.
[[nodiscard]] std::string read_file(const fs::path& path);
void write_file(const fs::path& path, const std::string& text);  // atomically: beside it, then renamed
[[nodiscard]] std::string format_number(double v);               // shortest text that reads back exactly
[[nodiscard]] std::string now_iso8601();

// JSON <-> Python through the json module: the documents are small, and this keeps one notion of
// JSON (Python's) on the Python side.
[[nodiscard]] py::object json_to_py(const nlohmann::json& j);
[[nodiscard]] nlohmann::json py_to_json(const py::handle& obj);

// Any array-like of numbers as doubles, each finite: "x[3] is not a finite number" otherwise.
[[nodiscard]] std::vector<double> finite_vector(const py::handle& obj, const char* name);
// A copy as a 1-D float64 numpy array.
[[nodiscard]] py::array_t<double> to_numpy(std::span<const double> v);

// FNV-1a over the numbers that define a model: a state is restored only into a model of the same
// table or parameters (restore_state alone cannot tell two tables of one grid apart).
[[nodiscard]] std::uint64_t fingerprint(const models::EverettTable& t);
[[nodiscard]] std::uint64_t fingerprint(const models::SmaParameters& p);

// source: how an error names the document (models/document_source.hpp): "table file 'T.json'".
[[nodiscard]] Table table_from_text(std::string_view text, const std::string& source = "table text");
[[nodiscard]] std::string table_text(const Table& t);  // as the CLI writes it: 2-space JSON and a newline
[[nodiscard]] Params params_from_text(std::string_view text, const std::string& source = "parameter text");
// A document read from path, named as the CLI names it.
[[nodiscard]] Table table_from_file(const fs::path& path);
[[nodiscard]] Params params_from_file(const fs::path& path);
[[nodiscard]] std::string params_text(const Params& p);
[[nodiscard]] py::dict transitions_to_dict(const models::SmaTransitions& t);
[[nodiscard]] Table make_table(models::EverettTable table, models::TableProvenance provenance);

void bind_table(py::module_& m);
void bind_params(py::module_& m);
void bind_model(py::module_& m);
void bind_identify(py::module_& m);
void bind_measures(py::module_& m);

}  // namespace hystlab::python
