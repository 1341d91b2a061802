// hystlab._hystlab: the module, and how C++ errors become Python exceptions.
//  - models::FormatError -> hystlab.FormatError (a ValueError), with the C++ message;
//  - std::invalid_argument -> ValueError (pybind11's own rule), with the C++ message;
//  - FileError -> the OSError of its errno (FileNotFoundError, PermissionError, ...), the CLI's text.
// The messages are the ones the CLI prints after "hystlab: error: ".
#include <cerrno>

#include "bindings.hpp"

namespace hystlab::python {
namespace {

PyObject* os_error_type(int code) {
  switch (code) {
    case ENOENT:
      return PyExc_FileNotFoundError;
    case EACCES:
    case EPERM:
      return PyExc_PermissionError;
    case EISDIR:
      return PyExc_IsADirectoryError;
    case ENOTDIR:
      return PyExc_NotADirectoryError;
    default:
      return PyExc_OSError;
  }
}

void translate_file_error(std::exception_ptr p) {
  try {
    if (p) std::rethrow_exception(p);
  } catch (const FileError& e) {
    // One argument, so str(error) is the message alone; errno is set for code that tests it.
    PyObject* type = os_error_type(e.code);
    py::object exc = py::reinterpret_borrow<py::object>(type)(e.what());
    exc.attr("errno") = e.code;
    PyErr_SetObject(type, exc.ptr());
  }
}

}  // namespace
}  // namespace hystlab::python

PYBIND11_MODULE(_hystlab, m) {
  using namespace hystlab::python;
  m.doc() = "hystlab's models: Everett tables, the simplified SMA model, identification and fits (docs/PYTHON.md)";
  m.attr("__version__") = HYSTLAB_VERSION;
  py::register_exception<hystlab::models::FormatError>(m, "FormatError", PyExc_ValueError);
  py::register_exception_translator(&translate_file_error);
  bind_table(m);
  bind_params(m);
  bind_model(m);
  bind_identify(m);
  bind_measures(m);
}
