/* hystlab C API: calibrated hysteresis models (Everett tables, simplified SMA model) for
 * simulation tools. One header, one shared library (-lhystlab, pkg-config hystlab, or CMake's
 * find_package(hystlab) and hystlab::hystlab).
 *
 * Every call returns a status; on failure hystlab_last_error() holds a message naming the
 * problem (per thread, valid until the thread's next failing call). Models are not shared
 * between threads: give each thread its own (hystlab_model_copy). */
#ifndef HYSTLAB_HYSTLAB_H
#define HYSTLAB_HYSTLAB_H

#include <stddef.h>
#include <stdint.h>

#if defined(HYSTLAB_BUILDING_LIBRARY)
#define HYSTLAB_API __attribute__((visibility("default")))
#else
#define HYSTLAB_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

#define HYSTLAB_API_VERSION 2 /* 2: hystlab_model_from_table */

typedef enum hystlab_status {
  HYSTLAB_OK = 0,
  HYSTLAB_ERROR_ARGUMENT = 1, /* a null pointer, or a value the call cannot take */
  HYSTLAB_ERROR_IO = 2,       /* the file cannot be read */
  HYSTLAB_ERROR_FORMAT = 3,   /* the document is not a valid table or parameter set */
  HYSTLAB_ERROR_MEMORY = 4
} hystlab_status;

typedef struct hystlab_model hystlab_model;

/* The library's version ("0.1.0") and the API version it implements. */
HYSTLAB_API const char* hystlab_version(void);
HYSTLAB_API int hystlab_api_version(void);

/* A model from a file or a JSON text: an Everett table ("format": "hystlab-everett-table") or
 * simplified-model parameters ("model": "simplified-sma"), as docs/FORMATS.md describes. The
 * model starts from rest (empty memory). */
HYSTLAB_API hystlab_status hystlab_model_load(const char* path, hystlab_model** out);
HYSTLAB_API hystlab_status hystlab_model_from_json(const char* json_text, hystlab_model** out);

/* A table from arrays, as the C header export (hystlab export --format h) defines them: n
 * subdivisions of [lo_mm, hi_mm] (nodes_mm NULL), or the grid's own n + 1 nodes (NAME_NODES_MM);
 * the (n+1)(n+2)/2 values F(delta_i, delta_j) in N at index i(i+1)/2 + j (NAME_VALUES_N); and the
 * force offset. The same model as the JSON document of that table, to the last digit. */
HYSTLAB_API hystlab_status hystlab_model_from_table(int n, double lo_mm, double hi_mm, const double* nodes_mm, const double* values_N, double force_offset_N,
                                                    hystlab_model** out);

/* Drive to displacement x (mm); *force_N receives the force. A table clamps inputs outside
 * its range and counts them (hystlab_model_saturations). x must be finite. */
HYSTLAB_API hystlab_status hystlab_model_step(hystlab_model* model, double x_mm, double* force_N);
/* force_N[k] = step(x_mm[k]) for k < n. */
HYSTLAB_API hystlab_status hystlab_model_evaluate(hystlab_model* model, const double* x_mm, double* force_N, size_t n);
/* Back to rest (empty memory). */
HYSTLAB_API hystlab_status hystlab_model_reset(hystlab_model* model);
/* A copy with the same state (memory included): continue two paths from one history. */
HYSTLAB_API hystlab_status hystlab_model_copy(const hystlab_model* model, hystlab_model** out);
HYSTLAB_API void hystlab_model_free(hystlab_model* model);

/* What the model is: 1 for an Everett table, 2 for the simplified SMA model. */
HYSTLAB_API int hystlab_model_kind(const hystlab_model* model);
HYSTLAB_API uint64_t hystlab_model_saturations(const hystlab_model* model);

HYSTLAB_API const char* hystlab_last_error(void);

#ifdef __cplusplus
}
#endif
#endif /* HYSTLAB_HYSTLAB_H */
