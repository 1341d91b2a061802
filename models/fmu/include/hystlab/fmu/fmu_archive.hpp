#pragma once
// An FMU (FMI 2.0 co-simulation) of a calibrated element, as the bytes of its .fmu archive: the
// runtime binary built with hystlab (binaries/linux64/hystlab_element.so, a $ORIGIN run path),
// the element's document as its resource, modelDescription.xml, documentation and licence.
// Pure: the caller writes the bytes (CLI) or sends them (HTTP). docs/FORMATS.md "FMU".
#include <string>
#include <string_view>

namespace hystlab::fmu {

struct FmuOptions {
  std::string model_name;  // empty: from the element ("hystlab_table" / "hystlab_sma")
  std::string created;     // ISO 8601 UTC, written as generationDateAndTime; empty: left out
};

// Throws models::FormatError naming the field when the document is neither a valid table nor
// valid simplified-model parameters (an unknown table version among them).
[[nodiscard]] std::string fmu_archive(std::string_view element_json, const FmuOptions& options = {});

// The runtime binary every FMU carries, as built with this hystlab.
[[nodiscard]] std::string_view fmu_runtime_binary();
inline constexpr std::string_view kModelIdentifier = "hystlab_element";

}  // namespace hystlab::fmu
