#pragma once
// The few HDF5 C API calls the run export needs, wrapped: handles close themselves, and every
// return value is checked and turned into one H5ExportError naming what could not be done.
#include <hdf5.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace hystlab::db::h5 {

[[noreturn]] void fail(const std::string& what);  // throws H5ExportError(write, "HDF5 could not " + what)
hid_t check(hid_t id, const std::string& what);
void check(herr_t rc, const std::string& what);
// HDF5 prints its error stack on stderr by default (per thread): our error says it in one line.
void silence_error_stack();

class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer closer, const std::string& what) : id_(check(id, what)), close_(closer) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& o) noexcept;
  ~Handle() { reset(); }
  [[nodiscard]] hid_t get() const noexcept { return id_; }
  // Closes now; a failed close of a file means data not written, so that one is checked.
  void close(const std::string& what);

 private:
  void reset() noexcept;
  hid_t id_ = H5I_INVALID_HID;
  Closer close_ = nullptr;
};

Handle create_file(const std::string& path);
Handle create_group(hid_t parent, const std::string& name);

// Attributes. Text is a fixed-length UTF-8 string (what Octave's load and every reader take).
void attr_text(hid_t obj, const std::string& name, const std::string& value);
void attr_double(hid_t obj, const std::string& name, double value);
void attr_int(hid_t obj, const std::string& name, std::int64_t value);
void attr_doubles(hid_t obj, const std::string& name, std::span<const double> values);

// Datasets written whole: a scalar text, a 1-D list of texts, a scalar number, a row-major matrix.
void dataset_text(hid_t parent, const std::string& name, const std::string& text);
void dataset_texts(hid_t parent, const std::string& name, const std::vector<std::string>& texts, int deflate_level);
Handle dataset_scalar(hid_t parent, const std::string& name, double value);
Handle dataset_matrix(hid_t parent, const std::string& name, std::size_t rows, std::size_t cols, const double* values);

// A 1-D dataset that grows: chunked, shuffled and deflated, unlimited in length.
class Column {
 public:
  enum class Type { f64, i64 };
  Column(hid_t parent, const std::string& name, Type type, std::size_t chunk, int deflate_level);
  void append(std::span<const double> values);
  void append(std::span<const std::int64_t> values);
  [[nodiscard]] hid_t id() const noexcept { return ds_.get(); }

 private:
  void append_raw(const void* data, std::size_t n, hid_t mem_type);
  std::string name_;
  Handle ds_;
  hsize_t size_ = 0;
};

// A column written whole (nodes, events' ids).
Handle write_column(hid_t parent, const std::string& name, std::span<const double> values, int deflate_level);
Handle write_column(hid_t parent, const std::string& name, std::span<const std::int64_t> values, int deflate_level);

}  // namespace hystlab::db::h5
