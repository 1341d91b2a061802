/* The C API from C: the header compiles as C, and the library's calls behave as documented. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "hystlab/hystlab.h"

static int failures = 0;
#define CHECK(cond)                                           \
  do {                                                        \
    if (!(cond)) {                                            \
      fprintf(stderr, "FAIL line %d: %s\n", __LINE__, #cond); \
      ++failures;                                             \
    }                                                         \
  } while (0)

static const char* kParams =
    "{\"model\": \"simplified-sma\", \"KA_N_per_mm\": 40, \"KM_N_per_mm\": 150, \"dtr_max_mm\": 2.95, \"C_N_per_degC\": 5.7,"
    " \"Mf0_degC\": 12.7, \"Ms0_degC\": 17.9, \"As0_degC\": 17.9, \"Af0_degC\": 21.5, \"T_degC\": 25}";

/* A 3-subdivision table on [0, 3] whose F(a, b) = 10·(a − b): a linear spring with a 10 N/mm slope. */
static const char* kTable =
    "{\"format\": \"hystlab-everett-table\", \"version\": 1, \"range_mm\": [0, 3], \"subdivisions\": 3,"
    " \"rows\": [[0], [10, 0], [20, 10, 0], [30, 20, 10, 0]]}";

/* The same spring on a grid of its own (format version 2: nodes 0, 0.5, 2, 3 mm). */
static const char* kTableNodes =
    "{\"format\": \"hystlab-everett-table\", \"version\": 2, \"range_mm\": [0, 3], \"subdivisions\": 3,"
    " \"nodes_mm\": [0, 0.5, 2, 3], \"rows\": [[0], [5, 0], [20, 15, 0], [30, 25, 10, 0]]}";

int main(void) {
  hystlab_model* m = NULL;
  double f = 0;
  CHECK(hystlab_api_version() == HYSTLAB_API_VERSION);
  CHECK(strcmp(hystlab_version(), "") != 0);

  CHECK(hystlab_model_from_json(kParams, &m) == HYSTLAB_OK);
  CHECK(hystlab_model_kind(m) == 2);
  CHECK(hystlab_model_step(m, 0.5, &f) == HYSTLAB_OK);
  CHECK(fabs(f - 20.0) < 1e-12); /* elastic austenite: KA · 0.5 mm */
  {
    double x[4] = {1.0, 3.0, 2.0, 0.0}, y[4], z[4];
    hystlab_model* c = NULL;
    CHECK(hystlab_model_copy(m, &c) == HYSTLAB_OK);
    CHECK(hystlab_model_evaluate(m, x, y, 4) == HYSTLAB_OK);
    for (int k = 0; k < 4; ++k) CHECK(hystlab_model_step(c, x[k], &z[k]) == HYSTLAB_OK);
    for (int k = 0; k < 4; ++k) CHECK(y[k] == z[k]); /* the copy carries the same memory */
    CHECK(hystlab_model_reset(c) == HYSTLAB_OK);
    CHECK(hystlab_model_step(c, 0.5, &f) == HYSTLAB_OK && fabs(f - 20.0) < 1e-12);
    hystlab_model_free(c);
  }
  hystlab_model_free(m);

  CHECK(hystlab_model_from_json(kTable, &m) == HYSTLAB_OK);
  if (m) {
    CHECK(hystlab_model_kind(m) == 1);
    CHECK(hystlab_model_step(m, 2.5, &f) == HYSTLAB_OK && fabs(f - 25.0) < 1e-12);
    CHECK(hystlab_model_step(m, 1.0, &f) == HYSTLAB_OK && fabs(f - 10.0) < 1e-12);
    CHECK(hystlab_model_step(m, 7.0, &f) == HYSTLAB_OK && fabs(f - 30.0) < 1e-12); /* clamped to 3 mm */
    CHECK(hystlab_model_saturations(m) == 1);
    CHECK(hystlab_model_step(m, NAN, &f) == HYSTLAB_ERROR_ARGUMENT);
    CHECK(strstr(hystlab_last_error(), "finite") != NULL);
    CHECK(hystlab_model_step(m, 1.0, NULL) == HYSTLAB_ERROR_ARGUMENT);
    {
      /* A table's copy steps its own table (the C API steps a table directly): the original
         freed first, the copy answers as a fresh model taken along the same inputs does. */
      double x[3] = {2.5, 1.0, 0.25}, y = 0, z = 0;
      hystlab_model *c = NULL, *fresh = NULL;
      CHECK(hystlab_model_reset(m) == HYSTLAB_OK);
      CHECK(hystlab_model_step(m, 2.0, &f) == HYSTLAB_OK);
      CHECK(hystlab_model_copy(m, &c) == HYSTLAB_OK);
      hystlab_model_free(m);
      m = NULL;
      CHECK(hystlab_model_from_json(kTable, &fresh) == HYSTLAB_OK);
      CHECK(c != NULL && fresh != NULL);
      if (c && fresh) {
        CHECK(hystlab_model_step(fresh, 2.0, &f) == HYSTLAB_OK);
        for (int k = 0; k < 3; ++k) {
          CHECK(hystlab_model_step(c, x[k], &y) == HYSTLAB_OK);
          CHECK(hystlab_model_step(fresh, x[k], &z) == HYSTLAB_OK);
          CHECK(y == z);
        }
        CHECK(fabs(y - 2.5) < 1e-12);
      }
      hystlab_model_free(c);
      hystlab_model_free(fresh);
    }
  }

  CHECK(hystlab_model_from_json(kTableNodes, &m) == HYSTLAB_OK);
  if (m) {
    CHECK(hystlab_model_step(m, 2.5, &f) == HYSTLAB_OK && fabs(f - 25.0) < 1e-12);
    CHECK(hystlab_model_step(m, 1.0, &f) == HYSTLAB_OK && fabs(f - 10.0) < 1e-12);
    CHECK(hystlab_model_step(m, 0.25, &f) == HYSTLAB_OK && fabs(f - 2.5) < 1e-12);
    hystlab_model_free(m);
  }

  m = (hystlab_model*)&f;
  CHECK(hystlab_model_load("/nonexistent/table.json", &m) == HYSTLAB_ERROR_IO);
  CHECK(m == NULL);
  CHECK(strstr(hystlab_last_error(), "/nonexistent/table.json") != NULL);
  CHECK(hystlab_model_from_json("{\"format\": \"hystlab-everett-table\", \"version\": 99}", &m) == HYSTLAB_ERROR_FORMAT);
  CHECK(strstr(hystlab_last_error(), "version") != NULL);
  CHECK(hystlab_model_from_json("[1, 2]", &m) == HYSTLAB_ERROR_FORMAT);
  CHECK(hystlab_model_from_json(NULL, &m) == HYSTLAB_ERROR_ARGUMENT);
  CHECK(hystlab_model_evaluate(NULL, NULL, NULL, 0) == HYSTLAB_ERROR_ARGUMENT);
  hystlab_model_free(NULL); /* like free(NULL) */

  if (failures == 0) printf("all checks passed\n");
  return failures == 0 ? 0 : 1;
}
