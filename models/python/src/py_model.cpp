// hystlab.Model: a table (PreisachModel) or simplified parameters (SimplifiedSmaModel) driven by
// displacement arrays, its memory kept between calls. The loop runs without the GIL on the
// concrete model type (both are final, so step() is inlined as in a C++ caller's loop); a mutex
// keeps two Python threads from driving one model at once.
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <optional>
#include <variant>

#include "bindings.hpp"
#include "hystlab/models/document_source.hpp"
#include "hystlab/models/preisach_model.hpp"

namespace hystlab::python {
namespace {

// A saved state: magic, the model's fingerprint, then save_state()'s numbers (native doubles).
constexpr char kStateMagic[8] = {'h', 'y', 's', 't', 's', 't', '0', '1'};

class Model {
 public:
  using Impl = std::variant<models::PreisachModel, models::SimplifiedSmaModel>;

  Model(const Table& t, double merge_tolerance, std::size_t max_turning_points)
      : table_(t),
        impl_(std::in_place_type<models::PreisachModel>, std::shared_ptr<const models::EverettTable>(t.doc, &t.doc->table),
              options(merge_tolerance, max_turning_points)),
        fingerprint_(fingerprint(t.table())) {}
  explicit Model(const Params& p) : params_(p), impl_(std::in_place_type<models::SimplifiedSmaModel>, p.p), fingerprint_(fingerprint(p.p)) {}
  Model(const Model& o) : table_(o.table_), params_(o.params_), impl_(o.locked_copy()), fingerprint_(o.fingerprint_) {}

  py::array_t<double> evaluate(const py::handle& obj, bool clamp, const py::object& out_obj);
  double step(double x, bool clamp) {
    if (!std::isfinite(x)) throw std::invalid_argument("x is not a finite number");
    if (!clamp && !clamp_ok(x)) throw std::invalid_argument(range_error("x", x));
    std::lock_guard lock(mu_);
    return std::visit([x](auto& m) { return m.step(x); }, impl_);
  }
  double peek(double x) const {
    if (!std::isfinite(x)) throw std::invalid_argument("x is not a finite number");
    std::lock_guard lock(mu_);
    return std::visit([x](const auto& m) { return m.peek(x); }, impl_);
  }
  void reset() {
    std::lock_guard lock(mu_);
    std::visit([](auto& m) { m.reset(); }, impl_);
  }
  template <class F>
  auto read(F&& f) const {
    std::lock_guard lock(mu_);
    return std::visit(std::forward<F>(f), impl_);
  }
  py::bytes state() const;
  void set_state(const py::bytes& blob);
  [[nodiscard]] const std::optional<Table>& table() const { return table_; }
  [[nodiscard]] const std::optional<Params>& params() const { return params_; }
  [[nodiscard]] std::string document() const { return table_ ? table_text(*table_) : params_text(*params_); }
  [[nodiscard]] const models::PreisachModel* preisach() const { return std::get_if<models::PreisachModel>(&impl_); }
  [[nodiscard]] const models::SimplifiedSmaModel* simplified() const { return std::get_if<models::SimplifiedSmaModel>(&impl_); }

 private:
  static models::PreisachOptions options(double merge_tolerance, std::size_t max_turning_points) {
    if (!(merge_tolerance >= 0.0) || !std::isfinite(merge_tolerance)) throw std::invalid_argument("merge_tolerance must be a finite number >= 0");
    // The memory is preallocated: a bound keeps a typo from asking for terabytes.
    if (max_turning_points < 3 || max_turning_points > (std::size_t{1} << 24)) throw std::invalid_argument("max_turning_points must be from 3 to 16777216");
    return models::PreisachOptions{merge_tolerance, max_turning_points};
  }
  Impl locked_copy() const {
    std::lock_guard lock(mu_);
    return impl_;
  }
  [[nodiscard]] bool clamp_ok(double x) const { return !table_ || (x >= table_->table().grid().lo && x <= table_->table().grid().hi); }
  [[nodiscard]] std::string range_error(const std::string& where, double x) const {
    const models::Grid& g = table_->table().grid();
    return where + ": displacement " + format_number(x) + " mm is outside the table's range " + format_number(g.lo) + ".." + format_number(g.hi) +
           " mm (clamp=True clamps and counts)";
  }

  std::optional<Table> table_;
  std::optional<Params> params_;
  Impl impl_;
  std::uint64_t fingerprint_;
  mutable std::mutex mu_;
};

// "x[3]" for a 1-D input, "x[1, 2]" for the element of flat index k of an N-d one.
std::string index_text(const py::array& a, std::size_t k) {
  std::vector<std::size_t> idx(static_cast<std::size_t>(a.ndim()));
  for (py::ssize_t d = a.ndim() - 1; d >= 0; --d) {
    const auto extent = static_cast<std::size_t>(a.shape(d));
    idx[static_cast<std::size_t>(d)] = k % extent;
    k /= extent;
  }
  std::string s = "x[";
  for (std::size_t d = 0; d < idx.size(); ++d) s += (d ? ", " : "") + std::to_string(idx[d]);
  return s + "]";
}

// The index of the first NaN or infinity, or n. Branch-free over blocks: the usual all-finite
// array costs about a cycle per sample, a few percent of a step.
std::size_t first_non_finite(const double* x, std::size_t n) {
  constexpr std::size_t kBlock = 512;
  for (std::size_t b = 0; b < n; b += kBlock) {
    const std::size_t e = std::min(n, b + kBlock);
    bool any = false;
    for (std::size_t k = b; k < e; ++k) any |= !(std::fabs(x[k]) <= std::numeric_limits<double>::max());
    if (any)
      for (std::size_t k = b; k < e; ++k)
        if (!std::isfinite(x[k])) return k;
  }
  return n;
}

// out: a float64 C-contiguous writeable array of x's size to write into (numpy's out=), which
// saves allocating (and the kernel zeroing) 8 bytes per sample on every call.
py::array_t<double> output_for(const py::array& in, const py::object& out_obj) {
  if (out_obj.is_none()) return py::array_t<double>(std::vector<py::ssize_t>(in.shape(), in.shape() + in.ndim()));
  if (!py::isinstance<py::array_t<double>>(out_obj)) throw py::type_error("out: must be a numpy array of float64");
  auto out = py::cast<py::array_t<double>>(out_obj);
  if (!(out.flags() & py::array::c_style) || !out.writeable() || out.size() != in.size())
    throw std::invalid_argument("out: must be a writeable C-contiguous float64 array of x's size (" + std::to_string(in.size()) + ")");
  return out;
}

py::array_t<double> Model::evaluate(const py::handle& obj, bool clamp, const py::object& out_obj) {
  const auto in = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  if (!in) throw std::invalid_argument("x: expected an array of numbers");
  py::array_t<double> out = output_for(in, out_obj);
  const double* x = in.data();
  double* f = out.mutable_data();
  const auto n = static_cast<std::size_t>(in.size());
  std::size_t bad = n;
  bool outside = false;
  {
    // Checked before any step, so a refused array leaves the memory as it was.
    py::gil_scoped_release release;
    bad = first_non_finite(x, n);
    for (std::size_t k = 0; k < n && bad == n && !clamp; ++k)
      if (!clamp_ok(x[k])) bad = k, outside = true;
    if (bad == n) {
      std::lock_guard lock(mu_);
      std::visit(
          [x, f, n](auto& m) {
            for (std::size_t k = 0; k < n; ++k) f[k] = m.step(x[k]);
          },
          impl_);
    }
  }
  if (bad < n) {
    const std::string where = in.ndim() == 0 ? std::string("x") : index_text(in, bad);
    throw std::invalid_argument(outside ? range_error(where, x[bad]) : where + " is not a finite number");
  }
  return out;
}

py::bytes Model::state() const {
  const std::vector<double> s = read([](const auto& m) { return m.save_state(); });
  std::string blob(kStateMagic, sizeof kStateMagic);
  blob.append(reinterpret_cast<const char*>(&fingerprint_), sizeof fingerprint_);
  blob.append(reinterpret_cast<const char*>(s.data()), s.size() * sizeof(double));
  return py::bytes(blob);
}

void Model::set_state(const py::bytes& b) {
  const std::string blob = b;
  constexpr std::size_t head = sizeof kStateMagic + sizeof(std::uint64_t);
  if (blob.size() < head || std::memcmp(blob.data(), kStateMagic, sizeof kStateMagic) != 0 || (blob.size() - head) % sizeof(double) != 0)
    throw std::invalid_argument("state: not a hystlab model state (use the bytes Model.state gave)");
  std::uint64_t fp = 0;
  std::memcpy(&fp, blob.data() + sizeof kStateMagic, sizeof fp);
  if (fp != fingerprint_)
    throw std::invalid_argument(std::string("state: saved from another ") + (table_ ? "table" : "model") +
                                " (its fingerprint differs from this model's); a state restores only into a model of the same " +
                                (table_ ? "table" : "parameters"));
  std::vector<double> s((blob.size() - head) / sizeof(double));
  std::memcpy(s.data(), blob.data() + head, s.size() * sizeof(double));
  std::lock_guard lock(mu_);
  std::visit([&s](auto& m) { m.restore_state(s); }, impl_);
}

// path: the file it was read from ("" for a pickled model's text), for the errors' names.
Model model_from_document(const std::string& text, double merge_tolerance, std::size_t max_turning_points, const std::string& path = "") {
  const auto j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_object() && j.contains("format"))
    return Model(table_from_text(text, path.empty() ? "table text" : models::file_source("table file", path)), merge_tolerance, max_turning_points);
  return Model(params_from_text(text, path.empty() ? "parameter text" : models::file_source("parameter file", path)));
}

py::tuple pickle_state(const Model& m) {
  const auto* p = m.preisach();
  return py::make_tuple(m.document(), p ? p->options().merge_tolerance : 0.0, p ? p->options().max_turning_points : 512, m.state());
}

Model unpickle(const py::tuple& t) {
  if (t.size() != 4) throw std::invalid_argument("Model: not a pickled hystlab.Model");
  Model m = model_from_document(py::cast<std::string>(t[0]), py::cast<double>(t[1]), py::cast<std::size_t>(t[2]));
  m.set_state(py::cast<py::bytes>(t[3]));
  return m;
}

}  // namespace

void bind_model(py::module_& m) {
  py::class_<Model>(m, "Model", "A hysteresis model driven by displacements (mm) giving forces (N); its memory is kept between calls.")
      .def(py::init<const Table&, double, std::size_t>(), py::arg("table"), py::kw_only(), py::arg("merge_tolerance") = 0.0,
           py::arg("max_turning_points") = 512)
      .def(py::init<const Params&>(), py::arg("params"))
      .def(py::init([](const fs::path& path, double merge_tolerance, std::size_t max_turning_points) {
             return model_from_document(read_file(path), merge_tolerance, max_turning_points, path.string());
           }),
           py::arg("path"), py::kw_only(), py::arg("merge_tolerance") = 0.0, py::arg("max_turning_points") = 512,
           "Model(\"T.json\") is Model.load(\"T.json\").")
      .def_static(
          "load",
          [](const fs::path& path, double merge_tolerance, std::size_t max_turning_points) {
            return model_from_document(read_file(path), merge_tolerance, max_turning_points, path.string());
          },
          py::arg("path"), py::kw_only(), py::arg("merge_tolerance") = 0.0, py::arg("max_turning_points") = 512,
          "A table document or parameters, told apart by the table's \"format\" field.")
      .def("evaluate", &Model::evaluate, py::arg("x"), py::arg("clamp") = true, py::arg("out") = py::none(),
           "Forces for the displacements x, in order, from the current memory (same shape as x, or written into out).")
      .def("__call__", &Model::evaluate, py::arg("x"), py::arg("clamp") = true, py::arg("out") = py::none())
      .def("step", &Model::step, py::arg("x"), py::arg("clamp") = true, "One displacement: the force (clamped and counted as evaluate).")
      .def("peek", &Model::peek, py::arg("x"), "The force step(x) would give, without moving.")
      .def("reset", &Model::reset, "Back to rest: the memory wiped, at the start of the range.")
      .def(
          "copy", [](const Model& self) { return Model(self); }, "An independent model in the same state (to branch a history).")
      .def("__copy__", [](const Model& self) { return Model(self); })
      .def(
          "__deepcopy__", [](const Model& self, const py::object&) { return Model(self); }, py::arg("memo"))
      .def_property("state", &Model::state, &Model::set_state, "The memory as bytes; assigning restores it (same table or parameters only).")
      .def_property_readonly("kind", [](const Model& self) { return self.preisach() ? "preisach" : "simplified"; })
      .def_property_readonly("table", [](const Model& self) { return self.table() ? py::cast(*self.table()) : py::none(); })
      .def_property_readonly("params", [](const Model& self) { return self.params() ? py::cast(*self.params()) : py::none(); })
      .def_property_readonly("range",
                             [](const Model& self) -> py::object {
                               if (!self.table()) return py::none();
                               return py::make_tuple(self.table()->table().grid().lo, self.table()->table().grid().hi);
                             })
      .def_property_readonly("input", [](const Model& self) { return self.read([](const auto& x) { return x.input(); }); })
      .def_property_readonly("output", [](const Model& self) { return self.read([](const auto& x) { return x.output(); }); })
      .def_property_readonly(
          "saturations", [](const Model& self) { return self.read([](const auto& x) { return x.saturation_count(); }); },
          "Inputs clamped to the table's range so far.")
      .def_property_readonly(
          "depth",
          [](const Model& self) -> py::object {
            if (const auto* p = self.preisach()) return py::int_(p->depth());
            return py::none();
          },
          "Turning points in the memory (a table model), else None.")
      .def_property_readonly("merges",
                             [](const Model& self) -> py::object {
                               if (const auto* p = self.preisach()) return py::int_(p->merge_count());
                               return py::none();
                             })
      .def_property_readonly("martensite_fraction",
                             [](const Model& self) -> py::object {
                               if (const auto* s = self.simplified()) return py::float_(s->martensite_fraction());
                               return py::none();
                             })
      .def("__repr__",
           [](const Model& self) {
             return self.preisach() ? "<hystlab.Model of a table, n=" + std::to_string(self.preisach()->table().grid().n) + ">"
                                    : std::string("<hystlab.Model of the simplified SMA model>");
           })
      .def(py::pickle(&pickle_state, &unpickle));
}

}  // namespace hystlab::python
