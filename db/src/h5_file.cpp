#include "h5_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "hystlab/db/run_h5.hpp"

namespace hystlab::db::h5 {

void fail(const std::string& what) { throw H5ExportError(H5ExportError::Kind::write, "HDF5 could not " + what); }
hid_t check(hid_t id, const std::string& what) {
  if (id < 0) fail(what);
  return id;
}
void check(herr_t rc, const std::string& what) {
  if (rc < 0) fail(what);
}
void silence_error_stack() { (void)H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

Handle& Handle::operator=(Handle&& o) noexcept {
  if (this != &o) {
    reset();
    id_ = o.id_, close_ = o.close_;
    o.id_ = H5I_INVALID_HID;
  }
  return *this;
}
void Handle::reset() noexcept {
  if (id_ >= 0 && close_ != nullptr) (void)close_(id_);
  id_ = H5I_INVALID_HID;
}
void Handle::close(const std::string& what) {
  const hid_t id = id_;
  id_ = H5I_INVALID_HID;
  if (id >= 0 && close_ != nullptr) check(close_(id), what);
}

namespace {
// A fixed-length string type of this many bytes (at least 1: HDF5 refuses a size of 0). Marked
// UTF-8 in attributes; in datasets marked ASCII (the bytes are still UTF-8), since Octave 7's
// load reads only that (HDF5 has no conversion from UTF-8 to the ASCII type it asks for).
Handle text_type(std::size_t bytes, H5T_cset_t cset = H5T_CSET_UTF8) {
  Handle t(H5Tcopy(H5T_C_S1), H5Tclose, "copy the string type");
  check(H5Tset_size(t.get(), std::max<std::size_t>(bytes, 1)), "size a string type");
  check(H5Tset_strpad(t.get(), H5T_STR_NULLPAD), "pad a string type");
  check(H5Tset_cset(t.get(), cset), "set a string type's character set");
  return t;
}
Handle scalar_space() { return {H5Screate(H5S_SCALAR), H5Sclose, "create a scalar dataspace"}; }
Handle simple_space(std::size_t n) {
  const hsize_t dims[1] = {n};
  return {H5Screate_simple(1, dims, nullptr), H5Sclose, "create a dataspace"};
}
// Chunked, shuffled and deflated, for a 1-D dataset that may grow.
Handle chunked(std::size_t chunk, int deflate_level, const std::string& name) {
  Handle p(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "create the properties of '" + name + "'");
  const hsize_t dims[1] = {std::max<std::size_t>(chunk, 1)};
  check(H5Pset_chunk(p.get(), 1, dims), "chunk '" + name + "'");
  if (deflate_level > 0) {
    check(H5Pset_shuffle(p.get()), "shuffle '" + name + "'");
    check(H5Pset_deflate(p.get(), static_cast<unsigned>(std::min(deflate_level, 9))), "compress '" + name + "' (deflate)");
  }
  return p;
}
void write_attr(hid_t obj, const std::string& name, hid_t file_type, hid_t mem_type, hid_t space, const void* data) {
  Handle a(H5Acreate2(obj, name.c_str(), file_type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose, "create the attribute '" + name + "'");
  check(H5Awrite(a.get(), mem_type, data), "write the attribute '" + name + "'");
}
}  // namespace

Handle create_file(const std::string& path) {
  errno = 0;
  const hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (f < 0) fail("create the file '" + path + "'" + (errno != 0 ? std::string(": ") + std::strerror(errno) : std::string()));
  return {f, H5Fclose, "create the file"};
}
Handle create_group(hid_t parent, const std::string& name) {
  return {H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "create the group '" + name + "'"};
}

void attr_text(hid_t obj, const std::string& name, const std::string& value) {
  const Handle t = text_type(value.size()), s = scalar_space();
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  write_attr(obj, name, t.get(), t.get(), s.get(), padded.data());
}
void attr_double(hid_t obj, const std::string& name, double value) {
  const Handle s = scalar_space();
  write_attr(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, s.get(), &value);
}
void attr_int(hid_t obj, const std::string& name, std::int64_t value) {
  const Handle s = scalar_space();
  write_attr(obj, name, H5T_STD_I64LE, H5T_NATIVE_INT64, s.get(), &value);
}
void attr_doubles(hid_t obj, const std::string& name, std::span<const double> values) {
  const Handle s = simple_space(values.size());
  write_attr(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, s.get(), values.data());
}

void dataset_text(hid_t parent, const std::string& name, const std::string& text) {
  const Handle t = text_type(text.size(), H5T_CSET_ASCII), s = scalar_space();
  const Handle d(H5Dcreate2(parent, name.c_str(), t.get(), s.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose, "create the dataset '" + name + "'");
  const std::string padded = text.empty() ? std::string(1, '\0') : text;
  check(H5Dwrite(d.get(), t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, padded.data()), "write the dataset '" + name + "'");
}

void dataset_texts(hid_t parent, const std::string& name, const std::vector<std::string>& texts, int deflate_level) {
  std::size_t width = 1;
  for (const std::string& s : texts) width = std::max(width, s.size());
  std::string block(width * texts.size(), '\0');  // fixed-length strings side by side, padded with NULs
  for (std::size_t k = 0; k < texts.size(); ++k) std::memcpy(block.data() + k * width, texts[k].data(), texts[k].size());
  const Handle t = text_type(width, H5T_CSET_ASCII), s = simple_space(texts.size());
  const Handle p = chunked(std::clamp<std::size_t>((1U << 20) / width, 1, std::max<std::size_t>(texts.size(), 1)), deflate_level, name);
  const Handle d(H5Dcreate2(parent, name.c_str(), t.get(), s.get(), H5P_DEFAULT, p.get(), H5P_DEFAULT), H5Dclose, "create the dataset '" + name + "'");
  if (!texts.empty()) check(H5Dwrite(d.get(), t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, block.data()), "write the dataset '" + name + "'");
}

Handle dataset_scalar(hid_t parent, const std::string& name, double value) {
  const Handle s = scalar_space();
  Handle d(H5Dcreate2(parent, name.c_str(), H5T_IEEE_F64LE, s.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose, "create the dataset '" + name + "'");
  check(H5Dwrite(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, &value), "write the dataset '" + name + "'");
  return d;
}

Handle dataset_matrix(hid_t parent, const std::string& name, std::size_t rows, std::size_t cols, const double* values) {
  const hsize_t dims[2] = {rows, cols};
  const Handle s(H5Screate_simple(2, dims, nullptr), H5Sclose, "create a dataspace");
  Handle d(H5Dcreate2(parent, name.c_str(), H5T_IEEE_F64LE, s.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose, "create the dataset '" + name + "'");
  check(H5Dwrite(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values), "write the dataset '" + name + "'");
  return d;
}

Column::Column(hid_t parent, const std::string& name, Type type, std::size_t chunk, int deflate_level) : name_(name) {
  const hsize_t dims[1] = {0}, max[1] = {H5S_UNLIMITED};
  const Handle s(H5Screate_simple(1, dims, max), H5Sclose, "create the dataspace of '" + name + "'");
  const Handle p = chunked(chunk, deflate_level, name);
  const hid_t file_type = type == Type::f64 ? H5T_IEEE_F64LE : H5T_STD_I64LE;
  ds_ = Handle(H5Dcreate2(parent, name.c_str(), file_type, s.get(), H5P_DEFAULT, p.get(), H5P_DEFAULT), H5Dclose, "create the dataset '" + name + "'");
}
void Column::append(std::span<const double> values) { append_raw(values.data(), values.size(), H5T_NATIVE_DOUBLE); }
void Column::append(std::span<const std::int64_t> values) { append_raw(values.data(), values.size(), H5T_NATIVE_INT64); }

void Column::append_raw(const void* data, std::size_t n, hid_t mem_type) {
  if (n == 0) return;
  const hsize_t start[1] = {size_}, count[1] = {n}, grown[1] = {size_ + n};
  check(H5Dset_extent(ds_.get(), grown), "extend the dataset '" + name_ + "'");
  const Handle file_space(H5Dget_space(ds_.get()), H5Sclose, "get the dataspace of '" + name_ + "'");
  check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr), "select rows of '" + name_ + "'");
  const Handle mem_space(H5Screate_simple(1, count, nullptr), H5Sclose, "create a dataspace");
  check(H5Dwrite(ds_.get(), mem_type, mem_space.get(), file_space.get(), H5P_DEFAULT, data), "write rows of '" + name_ + "'");
  size_ += n;
}

constexpr std::size_t kWholeChunk = 65536;  // elements: a chunk of 512 KiB, within HDF5's default 1 MiB chunk cache
Handle write_column(hid_t parent, const std::string& name, std::span<const double> values, int deflate_level) {
  Column c(parent, name, Column::Type::f64, std::clamp<std::size_t>(values.size(), 1, kWholeChunk), deflate_level);
  c.append(values);
  return Handle(H5Oopen(parent, name.c_str(), H5P_DEFAULT), H5Oclose, "open the dataset '" + name + "'");
}
Handle write_column(hid_t parent, const std::string& name, std::span<const std::int64_t> values, int deflate_level) {
  Column c(parent, name, Column::Type::i64, std::clamp<std::size_t>(values.size(), 1, kWholeChunk), deflate_level);
  c.append(values);
  return Handle(H5Oopen(parent, name.c_str(), H5P_DEFAULT), H5Oclose, "open the dataset '" + name + "'");
}

}  // namespace hystlab::db::h5
