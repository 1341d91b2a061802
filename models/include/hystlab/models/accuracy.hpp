#pragma once
// Accuracy measures of MODELS.md §4, overall and per branch direction.
#include <cstddef>
#include <optional>
#include <span>

namespace hystlab::models {

struct ErrorStats {
  std::size_t count = 0;
  double rms = 0.0;       // N
  double max_abs = 0.0;   // N
  double rms_norm = 0.0;  // rms / reference force range
  double max_norm = 0.0;  // max_abs / reference force range
};

struct AccuracyReport {
  ErrorStats overall, ascending, descending;  // a sample belongs to the direction of the input step into it
  double reference_range = 0.0;               // N
  // ∮ f dδ of reference and model, and the relative error, when the input returns to where it began.
  std::optional<double> energy_reference, energy_model, energy_rel_error;
};

// Sizes must match; throws std::invalid_argument otherwise.
[[nodiscard]] AccuracyReport compare(std::span<const double> input, std::span<const double> reference, std::span<const double> model);

// Trapezoidal ∫ f dδ along the path (the dissipated energy of the closed loops it contains), N·mm.
[[nodiscard]] double path_work(std::span<const double> input, std::span<const double> force) noexcept;

}  // namespace hystlab::models
