#pragma once
// Tables for other tools, as text (no I/O): CSV of the nodes, and a MATLAB/Octave script that
// builds the table and defines its evaluation with the same memory-stack rule as PreisachModel.
// The canonical, versioned format is the JSON of formats.hpp.
#include <string>

#include "hystlab/models/formats.hpp"

namespace hystlab::models {

// "# " header lines (format, grid, force offset, provenance), then i,j,alpha_mm,beta_mm,F_N.
[[nodiscard]] std::string table_to_csv(const EverettTable& table, const TableProvenance& provenance);

// A script: T = struct(lo, hi, n, force_offset, F) with F(i+1, j+1) = F(δ_i, δ_j) (NaN above the
// diagonal), then the functions hystlab_eval(T, x) and hystlab_everett(T, a, b) (MODELS.md §1).
[[nodiscard]] std::string table_to_matlab(const EverettTable& table, const TableProvenance& provenance);

// A C header: NAME_N, NAME_LO_MM, NAME_HI_MM, NAME_FORCE_OFFSET_N and NAME_VALUES_N[] (node
// (i, j) at index i(i+1)/2 + j), all static const; name must be a C identifier (FormatError).
[[nodiscard]] std::string table_to_c_header(const EverettTable& table, const TableProvenance& provenance, const std::string& name);

// Simplified-model parameters: name,value rows; a MATLAB/Octave struct P; C constants NAME_KA...
[[nodiscard]] std::string params_to_csv(const SmaParameters& p);
[[nodiscard]] std::string params_to_matlab(const SmaParameters& p);
[[nodiscard]] std::string params_to_c_header(const SmaParameters& p, const std::string& name);

}  // namespace hystlab::models
