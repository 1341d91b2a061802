// hystlab.Table and hystlab.Params: the documents of docs/FORMATS.md as Python objects.
#include <cmath>
#include <limits>

#include "bindings.hpp"
#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/table_export.hpp"
#include "hystlab/models/table_score.hpp"

namespace hystlab::python {
namespace {

py::dict provenance_dict(const models::TableProvenance& p) {
  py::dict d;
  d["source"] = p.source;
  d["method"] = p.method;
  d["created"] = p.created;
  d["from"] = p.from;
  d["details"] = json_to_py(p.extra);
  if (p.temperature_C) d["temperature_C"] = *p.temperature_C;  // when known (docs/FORMATS.md)
  return d;
}

models::TableProvenance provenance_from(const py::handle& obj) {
  models::TableProvenance p;
  if (obj.is_none()) return p;
  const auto d = py::cast<py::dict>(obj);
  for (const auto& [key, value] : d) {
    const std::string k = py::cast<std::string>(key);
    if (k == "details")
      p.extra = py_to_json(value);
    else if (k == "source")
      p.source = py::cast<std::string>(value);
    else if (k == "method")
      p.method = py::cast<std::string>(value);
    else if (k == "created")
      p.created = py::cast<std::string>(value);
    else if (k == "from")
      p.from = py::cast<std::string>(value);
    else if (k == "temperature_C") {
      const double t = py::cast<double>(value);
      if (!std::isfinite(t)) throw std::invalid_argument("provenance: temperature_C is not a finite number");
      p.temperature_C = t;
    } else
      throw std::invalid_argument("provenance: unknown key '" + k + "' (known: source, method, created, from, details, temperature_C)");
  }
  return p;
}

// values: the packed lower triangle ((n+1)(n+2)/2, node (i, j) at i(i+1)/2 + j) or the square
// (n+1)x(n+1) matrix whose lower triangle is read (what Table.matrix() gives).
Table table_from_arrays(const py::handle& nodes, const py::handle& values, double force_offset, const py::handle& provenance) {
  if (!std::isfinite(force_offset)) throw std::invalid_argument("force_offset is not a finite number");
  models::Grid grid = models::Grid::from_nodes(finite_vector(nodes, "nodes"));
  const auto v = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
  if (!v) throw std::invalid_argument("values: expected an array of numbers");
  std::vector<double> packed;
  const auto m = static_cast<py::ssize_t>(grid.n) + 1;
  if (v.ndim() == 2) {
    if (v.shape(0) != m || v.shape(1) != m)
      throw std::invalid_argument("values: a square matrix must be " + std::to_string(m) + " x " + std::to_string(m) + " for " + std::to_string(m) + " nodes");
    for (py::ssize_t i = 0; i < m; ++i)
      for (py::ssize_t j = 0; j <= i; ++j) packed.push_back(v.at(i, j));
  } else {
    packed.assign(v.data(), v.data() + v.size());
  }
  models::EverettTable t(std::move(grid), std::move(packed), force_offset);
  return make_table(std::move(t), provenance_from(provenance));
}

py::array_t<double> matrix(const Table& t) {
  const models::Grid& g = t.table().grid();
  const auto m = static_cast<py::ssize_t>(g.n) + 1;
  py::array_t<double> a({m, m});
  auto r = a.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < m; ++i)
    for (py::ssize_t j = 0; j < m; ++j)
      r(i, j) = j <= i ? t.table().node_value(static_cast<int>(i), static_cast<int>(j)) : std::numeric_limits<double>::quiet_NaN();
  return a;
}

// F(alpha, beta) at points (numpy broadcasting), clamped as EverettTable::value clamps.
py::object everett(const Table& t, const py::handle& alpha, const py::handle& beta) {
  py::module_ np = py::module_::import("numpy");
  py::tuple ab = np.attr("broadcast_arrays")(np.attr("asarray")(alpha, "float64"), np.attr("asarray")(beta, "float64"));
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(ab[0]);
  const auto b = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(ab[1]);
  py::array_t<double> out(std::vector<py::ssize_t>(a.shape(), a.shape() + a.ndim()));
  double* o = out.mutable_data();
  for (py::ssize_t k = 0; k < a.size(); ++k) {
    if (!std::isfinite(a.data()[k]) || !std::isfinite(b.data()[k])) throw std::invalid_argument("point " + std::to_string(k) + " is not a finite number");
    o[k] = t.table().value(a.data()[k], b.data()[k]);
  }
  if (a.ndim() == 0) return py::float_(o[0]);
  return out;
}

py::list cell_weights(const Table& t) {
  py::list out;
  for (const auto& c : models::cell_weights(t.table())) out.append(py::make_tuple(c.p, c.q, c.weight));
  return out;
}

bool same_table(const Table& a, const Table& b) {
  const auto& x = a.table();
  const auto& y = b.table();
  return x.grid().same_nodes(y.grid()) && x.force_offset() == y.force_offset() &&
         std::equal(x.values().begin(), x.values().end(), y.values().begin(), y.values().end());
}

py::dict transitions_dict(const models::SmaTransitions& t) {
  py::dict d;
  for (const auto& [name, pt] : {std::pair{"Ms", t.Ms}, {"Mf", t.Mf}, {"As", t.As}, {"Af", t.Af}}) d[name] = py::make_tuple(pt.displacement, pt.force);
  return d;
}

std::string table_repr(const Table& t) {
  const models::Grid& g = t.table().grid();
  return "<hystlab.Table n=" + std::to_string(g.n) + " on " + format_number(g.lo) + ".." + format_number(g.hi) + " mm" +
         (g.uniform() ? "" : " (nodes of its own)") + ", method " + (t.doc->provenance.method.empty() ? "?" : t.doc->provenance.method) + ">";
}

}  // namespace

py::dict transitions_to_dict(const models::SmaTransitions& t) { return transitions_dict(t); }

void bind_table(py::module_& m) {
  py::class_<Table>(m, "Table", "An Everett (FOT) table with its provenance: docs/FORMATS.md, versions 1 and 2.")
      .def(py::init(&table_from_arrays), py::arg("nodes"), py::arg("values"), py::arg("force_offset") = 0.0, py::arg("provenance") = py::none(),
           "A table from its grid nodes and F values (packed lower triangle, or the square matrix's lower triangle).")
      .def_static(
          "load", [](const fs::path& path) { return table_from_file(path); }, py::arg("path"))
      .def_static(
          "from_json", [](std::string_view text) { return table_from_text(text); }, py::arg("text"))
      .def(
          "save", [](const Table& t, const fs::path& path) { write_file(path, table_text(t)); }, py::arg("path"))
      .def("to_json", &table_text, "The document as `hystlab identify` writes it.")
      .def("to_csv", [](const Table& t) { return models::table_to_csv(t.table(), t.doc->provenance); })
      .def("to_matlab", [](const Table& t) { return models::table_to_matlab(t.table(), t.doc->provenance); })
      .def(
          "to_c_header", [](const Table& t, const std::string& name) { return models::table_to_c_header(t.table(), t.doc->provenance, name); }, py::arg("name"))
      .def_property_readonly("n", [](const Table& t) { return t.table().grid().n; })
      .def_property_readonly("lo", [](const Table& t) { return t.table().grid().lo; })
      .def_property_readonly("hi", [](const Table& t) { return t.table().grid().hi; })
      .def_property_readonly("range", [](const Table& t) { return py::make_tuple(t.table().grid().lo, t.table().grid().hi); })
      .def_property_readonly("uniform", [](const Table& t) { return t.table().grid().uniform(); })
      .def_property_readonly("version", [](const Table& t) { return t.table().grid().uniform() ? models::kTableVersion : models::kTableVersionNodes; })
      .def_property_readonly("nodes", [](const Table& t) { return to_numpy(t.table().grid().nodes()); })
      .def_property_readonly(
          "values", [](const Table& t) { return to_numpy(t.table().values()); }, "F(δ_i, δ_j) for j <= i, packed: node (i, j) at i(i+1)/2 + j (a copy).")
      .def("matrix", &matrix, "F as an (n+1) x (n+1) array, F[i, j] = F(δ_i, δ_j), NaN above the diagonal.")
      .def_property_readonly("force_offset", [](const Table& t) { return t.table().force_offset(); })
      .def_property(
          "provenance", [](const Table& t) { return provenance_dict(t.doc->provenance); },
          [](Table& t, const py::handle& d) { t.doc->provenance = provenance_from(d); })
      .def("everett", &everett, py::arg("alpha"), py::arg("beta"), "F(α, β) by the table's interpolation (inputs clamped to the grid).")
      .def("cell_weights", &cell_weights, "[(p, q, weight_N)]: the Preisach mass of every cell.")
      .def(
          "score",
          [](const Table& t, const py::handle& x, const py::handle& f) {
            const auto xv = finite_vector(x, "x"), fv = finite_vector(f, "f");
            return json_to_py(models::accuracy_json(models::score_table(t.table(), xv, fv)));
          },
          py::arg("x"), py::arg("f"), "The table from rest over x against the measured f (as GET /api/tables/ID/score).")
      .def("__eq__", [](const Table& a, const py::object& b) { return py::isinstance<Table>(b) && same_table(a, py::cast<const Table&>(b)); })
      .def("__ne__", [](const Table& a, const py::object& b) { return !(py::isinstance<Table>(b) && same_table(a, py::cast<const Table&>(b))); })
      .def("__repr__", &table_repr)
      .def(py::pickle([](const Table& t) { return py::make_tuple(table_text(t)); },
                      [](const py::tuple& s) { return table_from_text(py::cast<std::string>(s[0])); }));
  py::setattr(m.attr("Table"), "__hash__", py::none());
}

void bind_params(py::module_& m) {
  using models::SmaParameters;
  py::class_<Params>(m, "Params", "Simplified SMA model parameters (docs/FORMATS.md); the paper's Table 1 by default.")
      .def(py::init([](double KA, double KM, double dtr_max, double C, double Mf0, double Ms0, double As0, double Af0, double T, std::string source) {
             Params p{SmaParameters{KA, KM, dtr_max, C, Mf0, Ms0, As0, Af0, T}, std::move(source)};
             models::validate(p.p);
             return p;
           }),
           py::kw_only(), py::arg("KA") = 40.0, py::arg("KM") = 150.0, py::arg("dtr_max") = 2.95, py::arg("C") = 5.7, py::arg("Mf0") = 12.7,
           py::arg("Ms0") = 17.9, py::arg("As0") = 17.9, py::arg("Af0") = 21.5, py::arg("T") = 25.0, py::arg("source") = "")
      .def_static(
          "load", [](const fs::path& path) { return params_from_file(path); }, py::arg("path"))
      .def_static(
          "from_json", [](std::string_view text) { return params_from_text(text); }, py::arg("text"))
      .def(
          "save", [](const Params& p, const fs::path& path) { write_file(path, params_text(p)); }, py::arg("path"))
      .def("to_json", &params_text)
      .def("to_csv", [](const Params& p) { return models::params_to_csv(p.p); })
      .def("to_matlab", [](const Params& p) { return models::params_to_matlab(p.p); })
      .def(
          "to_c_header", [](const Params& p, const std::string& name) { return models::params_to_c_header(p.p, name); }, py::arg("name"))
      .def_property_readonly(
          "KA", [](const Params& p) { return p.p.KA; }, "N/mm")
      .def_property_readonly(
          "KM", [](const Params& p) { return p.p.KM; }, "N/mm")
      .def_property_readonly(
          "dtr_max", [](const Params& p) { return p.p.dtr_max; }, "mm")
      .def_property_readonly(
          "C", [](const Params& p) { return p.p.C; }, "N/°C")
      .def_property_readonly(
          "Mf0", [](const Params& p) { return p.p.Mf0; }, "°C")
      .def_property_readonly(
          "Ms0", [](const Params& p) { return p.p.Ms0; }, "°C")
      .def_property_readonly(
          "As0", [](const Params& p) { return p.p.As0; }, "°C")
      .def_property_readonly(
          "Af0", [](const Params& p) { return p.p.Af0; }, "°C")
      .def_property_readonly(
          "T", [](const Params& p) { return p.p.T; }, "°C")
      .def_readwrite("source", &Params::source)
      .def(
          "transitions", [](const Params& p) { return transitions_dict(models::transitions(p.p)); },
          "{'Ms': (mm, N), 'Mf': ..., 'As': ..., 'Af': ...}: the transformation points at T.")
      .def("__eq__",
           [](const Params& a, const py::object& b) {
             if (!py::isinstance<Params>(b)) return false;
             const SmaParameters& x = a.p;
             const SmaParameters& y = py::cast<const Params&>(b).p;
             return x.KA == y.KA && x.KM == y.KM && x.dtr_max == y.dtr_max && x.C == y.C && x.Mf0 == y.Mf0 && x.Ms0 == y.Ms0 && x.As0 == y.As0 &&
                    x.Af0 == y.Af0 && x.T == y.T;
           })
      .def("__repr__",
           [](const Params& p) {
             const SmaParameters& q = p.p;
             return "hystlab.Params(KA=" + format_number(q.KA) + ", KM=" + format_number(q.KM) + ", dtr_max=" + format_number(q.dtr_max) +
                    ", C=" + format_number(q.C) + ", Mf0=" + format_number(q.Mf0) + ", Ms0=" + format_number(q.Ms0) + ", As0=" + format_number(q.As0) +
                    ", Af0=" + format_number(q.Af0) + ", T=" + format_number(q.T) + ")";
           })
      .def(py::pickle([](const Params& p) { return py::make_tuple(params_text(p)); },
                      [](const py::tuple& s) { return params_from_text(py::cast<std::string>(s[0])); }));
  py::setattr(m.attr("Params"), "__hash__", py::none());
}

}  // namespace hystlab::python
