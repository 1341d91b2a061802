#include "hystlab/models/table_score.hpp"

#include <vector>

#include "hystlab/models/preisach_model.hpp"

namespace hystlab::models {

AccuracyReport score_table(const EverettTable& table, std::span<const double> x, std::span<const double> f) {
  PreisachModel m(table);
  std::vector<double> y(x.size());
  m.evaluate(x, y);
  return compare(x, f, y);
}

nlohmann::json accuracy_json(const AccuracyReport& r) {
  using nlohmann::json;
  auto branch = [](const ErrorStats& s) {
    return json{{"samples", s.count}, {"rms_N", s.rms}, {"max_N", s.max_abs}, {"rms_norm", s.rms_norm}, {"max_norm", s.max_norm}};
  };
  json j{{"overall", branch(r.overall)}, {"ascending", branch(r.ascending)}, {"descending", branch(r.descending)}, {"reference_range_N", r.reference_range}};
  if (r.energy_rel_error) j["loop_energy_rel_error"] = *r.energy_rel_error;
  return j;
}

}  // namespace hystlab::models
