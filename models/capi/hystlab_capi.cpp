// The C API over hystlab::models: exceptions and error codes stop here.
#include <cmath>
#include <fstream>
#include <memory>
#include <new>
#include <sstream>
#include <string>

#include "hystlab/hystlab.h"
#include "hystlab/models/element.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/preisach_model.hpp"

struct hystlab_model {
  std::unique_ptr<hystlab::models::HysteresisModel> model;
  int kind = 0;
  // The model as a table, when it is one: its step called directly, inlined (PreisachModel is
  // final), not through the interface's virtual call (issue 27: the C API is the FMU's and the
  // Python module's yardstick, and a table is what most callers step).
  hystlab::models::PreisachModel* table = nullptr;
  void adopt(std::unique_ptr<hystlab::models::HysteresisModel> m) {
    model = std::move(m);
    table = dynamic_cast<hystlab::models::PreisachModel*>(model.get());
  }
  double step(double x) noexcept { return table ? table->step(x) : model->step(x); }
};

namespace {
thread_local std::string g_error;

hystlab_status fail(hystlab_status s, std::string message) {
  g_error = std::move(message);
  return s;
}

// Runs f, turning every exception into a status and a message.
template <class F>
hystlab_status guarded(F&& f) noexcept {
  try {
    return f();
  } catch (const hystlab::models::FormatError& e) {
    return fail(HYSTLAB_ERROR_FORMAT, e.what());
  } catch (const std::invalid_argument& e) {
    return fail(HYSTLAB_ERROR_FORMAT, e.what());
  } catch (const std::bad_alloc&) {
    return fail(HYSTLAB_ERROR_MEMORY, "out of memory");
  } catch (const std::exception& e) {
    return fail(HYSTLAB_ERROR_ARGUMENT, e.what());
  }
}

hystlab_status make(const std::string& text, hystlab_model** out) {
  hystlab::models::Element e = hystlab::models::element_from_json(text);
  auto m = std::make_unique<hystlab_model>();
  m->adopt(std::move(e.model));
  m->kind = static_cast<int>(e.kind);
  *out = m.release();
  return HYSTLAB_OK;
}
}  // namespace

extern "C" {

const char* hystlab_version(void) { return HYSTLAB_VERSION; }
int hystlab_api_version(void) { return HYSTLAB_API_VERSION; }
const char* hystlab_last_error(void) { return g_error.c_str(); }

hystlab_status hystlab_model_load(const char* path, hystlab_model** out) {
  if (!path || !out) return fail(HYSTLAB_ERROR_ARGUMENT, "hystlab_model_load: null argument");
  *out = nullptr;
  return guarded([&] {
    std::ifstream in(path, std::ios::binary);
    if (!in) return fail(HYSTLAB_ERROR_IO, std::string("cannot open '") + path + "'");
    std::stringstream s;
    s << in.rdbuf();
    const hystlab_status st = make(s.str(), out);
    if (st != HYSTLAB_OK) g_error = std::string(path) + ": " + g_error;
    return st;
  });
}

hystlab_status hystlab_model_from_json(const char* text, hystlab_model** out) {
  if (!text || !out) return fail(HYSTLAB_ERROR_ARGUMENT, "hystlab_model_from_json: null argument");
  *out = nullptr;
  return guarded([&] { return make(text, out); });
}

hystlab_status hystlab_model_from_table(int n, double lo, double hi, const double* nodes, const double* values, double offset, hystlab_model** out) {
  if (!values || !out) return fail(HYSTLAB_ERROR_ARGUMENT, "hystlab_model_from_table: null argument");
  *out = nullptr;
  if (n < 1 || n > 100000) return fail(HYSTLAB_ERROR_ARGUMENT, "hystlab_model_from_table: n = " + std::to_string(n) + " is not in 1..100000");
  return guarded([&] {
    namespace hm = hystlab::models;
    const std::size_t count = static_cast<std::size_t>(n + 1) * static_cast<std::size_t>(n + 2) / 2;
    const hm::Grid grid = nodes ? hm::Grid::from_nodes(std::vector<double>(nodes, nodes + n + 1)) : hm::Grid::make(lo, hi, n);
    if (nodes && (grid.lo != lo || grid.hi != hi))
      return fail(HYSTLAB_ERROR_FORMAT,
                  "hystlab_model_from_table: the nodes run from " + std::to_string(grid.lo) + " to " + std::to_string(grid.hi) + ", not from lo_mm to hi_mm");
    auto m = std::make_unique<hystlab_model>();
    m->adopt(std::make_unique<hm::PreisachModel>(hm::EverettTable(grid, std::vector<double>(values, values + count), offset)));
    m->kind = 1;
    *out = m.release();
    return HYSTLAB_OK;
  });
}

hystlab_status hystlab_model_step(hystlab_model* m, double x, double* force) {
  if (!m || !force) return fail(HYSTLAB_ERROR_ARGUMENT, "hystlab_model_step: null argument");
  if (!std::isfinite(x)) return fail(HYSTLAB_ERROR_ARGUMENT, "hystlab_model_step: the displacement is not a finite number");
  *force = m->step(x);
  return HYSTLAB_OK;
}

hystlab_status hystlab_model_evaluate(hystlab_model* m, const double* x, double* force, size_t n) {
  if (!m || (n > 0 && (!x || !force))) return fail(HYSTLAB_ERROR_ARGUMENT, "hystlab_model_evaluate: null argument");
  for (size_t k = 0; k < n; ++k)
    if (!std::isfinite(x[k])) return fail(HYSTLAB_ERROR_ARGUMENT, "hystlab_model_evaluate: x[" + std::to_string(k) + "] is not a finite number");
  for (size_t k = 0; k < n; ++k) force[k] = m->step(x[k]);
  return HYSTLAB_OK;
}

hystlab_status hystlab_model_reset(hystlab_model* m) {
  if (!m) return fail(HYSTLAB_ERROR_ARGUMENT, "hystlab_model_reset: null model");
  m->model->reset();
  return HYSTLAB_OK;
}

hystlab_status hystlab_model_copy(const hystlab_model* m, hystlab_model** out) {
  if (!m || !out) return fail(HYSTLAB_ERROR_ARGUMENT, "hystlab_model_copy: null argument");
  *out = nullptr;
  return guarded([&] {
    auto c = std::make_unique<hystlab_model>();
    c->adopt(m->model->clone());
    c->kind = m->kind;
    *out = c.release();
    return HYSTLAB_OK;
  });
}

void hystlab_model_free(hystlab_model* m) { delete m; }

int hystlab_model_kind(const hystlab_model* m) { return m ? m->kind : 0; }
uint64_t hystlab_model_saturations(const hystlab_model* m) { return m ? m->model->saturation_count() : 0; }

}  // extern "C"
