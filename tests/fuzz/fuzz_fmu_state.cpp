// libFuzzer: a serialized FMU state (fmi2DeSerializeFMUstate's bytes) is refused with
// std::invalid_argument or taken into a model that then steps, never a crash. The decoder and the
// model's restore_state are both reached: the numbers after the instance's nine are the model's.
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>

#include "../../models/fmu/src/fmu_state.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/simplified_sma.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace hm = hystlab::models;
  static const hm::EverettTable table(hm::Grid::make(0.0, 4.0, 8));
  static const hm::EverettTable refined(hm::Grid::refined(0.0, 4.0, 8, 2.0, 1.0));  // a grid of its own: cells by search
  try {
    const hystlab::fmu::StateRecord r = hystlab::fmu::decode_state({reinterpret_cast<const char*>(data), size});
    if (r.numbers.size() < 9) return 0;
    const std::span<const double> model_state = std::span<const double>(r.numbers).subspan(9);
    hm::PreisachModel p(table), q(refined);
    hm::SimplifiedSmaModel s(hm::table1_parameters());
    for (hm::HysteresisModel* m : {static_cast<hm::HysteresisModel*>(&p), static_cast<hm::HysteresisModel*>(&q), static_cast<hm::HysteresisModel*>(&s)}) {
      try {
        m->restore_state(model_state);
        for (const double x : {0.0, 3.0, 1.0, 2.0}) (void)m->step(x);  // a state taken must step
      } catch (const std::invalid_argument&) {
      }
    }
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
