#pragma once
// The FMU's variables, named once: the runtime answers to these value references and the
// packager writes them into modelDescription.xml (docs/FORMATS.md "FMU").
#include <array>
#include <string_view>

namespace hystlab::fmu {

enum class VarType { Real, Integer };

struct Variable {
  std::string_view name;
  unsigned vr;  // value reference
  VarType type;
  std::string_view causality, variability;
  std::string_view unit;  // "" for none
  double start;           // used when has_start
  bool has_start;
  std::string_view description;
};

enum Ref : unsigned { kX = 0, kF = 1, kXScale = 2, kXOffset = 3, kForceScale = 4, kSign = 5, kSaturations = 6 };

inline constexpr std::array<Variable, 7> kVariables{{
    {"x", kX, VarType::Real, "input", "continuous", "", 0.0, true,
     "displacement of the element, in input units: the model sees x * x_scale_mm + x_offset_mm millimetres"},
    {"F", kF, VarType::Real, "output", "continuous", "N", 0.0, false, "force of the element: sign * force_scale * the calibrated force (N)"},
    {"x_scale_mm", kXScale, VarType::Real, "parameter", "fixed", "", 1.0, true, "millimetres per input unit: 1 when x is in mm, 1000 when x is in metres"},
    {"x_offset_mm", kXOffset, VarType::Real, "parameter", "fixed", "mm", 0.0, true,
     "added to the scaled input, in mm (a preload, or where x = 0 sits on the table)"},
    {"force_scale", kForceScale, VarType::Real, "parameter", "fixed", "", 1.0, true, "multiplies the force (springs in parallel, a unit other than N)"},
    {"sign", kSign, VarType::Integer, "parameter", "fixed", "", 1.0, true,
     "+1 or -1: the sign convention of F (-1 gives the force the element exerts on its mount)"},
    {"saturations", kSaturations, VarType::Integer, "output", "discrete", "", 0.0, false,
     "inputs clamped to the table's range so far (0 for the simplified model)"},
}};

}  // namespace hystlab::fmu
