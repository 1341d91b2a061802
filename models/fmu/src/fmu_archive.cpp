#include "hystlab/fmu/fmu_archive.hpp"

#include <charconv>
#include <nlohmann/json.hpp>

#include "fmu_guid.hpp"
#include "fmu_variables.hpp"
#include "hystlab/models/element.hpp"
#include "hystlab/models/text_forms.hpp"
#include "zip_writer.hpp"

#ifndef HYSTLAB_VERSION
#define HYSTLAB_VERSION "unknown"
#endif

namespace hystlab::fmu {
namespace {
std::string xml_escaped(std::string_view s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\n':
        out += "&#10;";
        break;
      default:
        if (static_cast<unsigned char>(c) >= 0x20 || c == '\t') out.push_back(c);  // XML 1.0 has no other control characters
    }
  }
  return out;
}

std::string num(double v) { return models::exact_text(v); }

// One line on what the element is, from its document (the table's provenance, or the parameters).
std::string element_summary(const models::Element& e) {
  const auto j = nlohmann::json::parse(e.canonical_json);
  if (e.kind == models::ElementKind::Params)
    return "simplified SMA model (MODELS.md section 2), KA " + num(j.value("KA_N_per_mm", 0.0)) + " N/mm, KM " + num(j.value("KM_N_per_mm", 0.0)) +
           " N/mm, T " + num(j.value("T_degC", 0.0)) + " degC";
  const auto& p = j.contains("provenance") ? j["provenance"] : nlohmann::json::object();
  return "Everett table, n = " + std::to_string(j.value("subdivisions", 0)) + " on [" + num(e.lo_mm) + ", " + num(e.hi_mm) + "] mm, method " +
         p.value("method", std::string("?")) + ", from " + p.value("from", std::string("?")) + ", created " + p.value("created", std::string("?"));
}

std::string variables_xml(const models::Element& e) {
  std::string x;
  for (const Variable& v : kVariables) {
    x += "    <ScalarVariable name=\"" + std::string(v.name) + "\" valueReference=\"" + std::to_string(v.vr) + "\" causality=\"" + std::string(v.causality) +
         "\" variability=\"" + std::string(v.variability) + "\"";
    if (v.causality == "parameter") x += " initial=\"exact\"";
    x += " description=\"" + xml_escaped(v.description) + "\">\n      <" + (v.type == VarType::Real ? "Real" : "Integer");
    if (!v.unit.empty()) x += " unit=\"" + std::string(v.unit) + "\"";
    // x starts at rest: the table's lower end (in mm, for the default x_scale_mm = 1).
    const double start = v.vr == kX ? e.rest_input_mm : v.start;
    if (v.has_start) x += " start=\"" + (v.type == VarType::Real ? num(start) : std::to_string(static_cast<int>(start))) + "\"";
    x += "/>\n    </ScalarVariable>\n";
  }
  return x;
}

std::string model_description(const models::Element& e, const std::string& guid, const FmuOptions& o) {
  const std::string name = !o.model_name.empty() ? o.model_name : e.kind == models::ElementKind::Table ? "hystlab_table" : "hystlab_sma";
  std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<fmiModelDescription fmiVersion=\"2.0\" modelName=\"" + xml_escaped(name) + "\" guid=\"" + guid +
                  "\" description=\"" + xml_escaped("hysteresis element: " + element_summary(e)) + "\" generationTool=\"hystlab " HYSTLAB_VERSION "\"";
  if (!o.created.empty()) x += " generationDateAndTime=\"" + xml_escaped(o.created) + "\"";
  x += " variableNamingConvention=\"flat\" numberOfEventIndicators=\"0\">\n";
  x += "  <CoSimulation modelIdentifier=\"" + std::string(kModelIdentifier) +
       "\" needsExecutionTool=\"false\" canHandleVariableCommunicationStepSize=\"true\" canInterpolateInputs=\"true\""
       " maxOutputDerivativeOrder=\"0\" canRunAsynchronuously=\"false\" canBeInstantiatedOnlyOncePerProcess=\"false\""
       " canNotUseMemoryManagementFunctions=\"true\" canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"true\""
       " providesDirectionalDerivative=\"false\"/>\n";
  x += "  <UnitDefinitions>\n    <Unit name=\"mm\"><BaseUnit m=\"1\" factor=\"0.001\"/></Unit>\n"
       "    <Unit name=\"N\"><BaseUnit kg=\"1\" m=\"1\" s=\"-2\"/></Unit>\n  </UnitDefinitions>\n";
  x += "  <LogCategories>\n    <Category name=\"logStatusWarning\" description=\"inputs clamped to the table's range\"/>\n"
       "    <Category name=\"logStatusError\" description=\"refused calls, with the reason\"/>\n"
       "    <Category name=\"logStatusFatal\" description=\"out of memory\"/>\n  </LogCategories>\n";
  x += "  <ModelVariables>\n" + variables_xml(e) + "  </ModelVariables>\n";
  // 1-based indices into ModelVariables: x 1, F 2, x_scale_mm 3, x_offset_mm 4, force_scale 5, sign 6, saturations 7.
  // F follows x at once (read after fmi2SetReal, it is the force there); saturations counts the
  // inputs taken by steps, so it depends on no input directly (and is 0 until initialization ends).
  x += "  <ModelStructure>\n    <Outputs>\n      <Unknown index=\"2\" dependencies=\"1\"/>\n      <Unknown index=\"7\" dependencies=\"\"/>\n"
       "    </Outputs>\n    <InitialUnknowns>\n      <Unknown index=\"2\" dependencies=\"1 3 4 5 6\"/>\n"
       "      <Unknown index=\"7\" dependencies=\"\"/>\n    </InitialUnknowns>\n  </ModelStructure>\n";
  return x + "</fmiModelDescription>\n";
}

std::string documentation(const models::Element& e, const std::string& guid) {
  return "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>hystlab element</title></head><body>\n<h1>A calibrated hysteresis element</h1>\n<p>" +
         xml_escaped(element_summary(e)) + ". GUID " + guid +
         ", written by hystlab " HYSTLAB_VERSION
         ".</p>\n<h2>Variables</h2>\n<ul>\n<li><b>x</b> (input): the displacement; the model sees <i>x &times; x_scale_mm + x_offset_mm</i> mm "
         "(x_scale_mm = 1000 takes x in metres).</li>\n<li><b>F</b> (output, N): <i>sign &times; force_scale &times;</i> the calibrated force. F "
         "depends on x directly: read after fmi2SetReal, it is the force at the new input without taking it into the memory; fmi2DoStep takes "
         "it.</li>\n<li><b>saturations</b> (output): inputs outside the table's range, clamped and counted.</li>\n</ul>\n"
         "<h2>The input within a step</h2>\n<p>The element is rate-independent: its force depends on the input's path only through the path's "
         "turning points. An input set by fmi2SetReal is held over the step (it is reached at the step's start). With fmi2SetRealInputDerivatives "
         "(orders 1 and 2) the input follows x + x'&tau; + x''&tau;&sup2;/2 over the step; when that turns inside the step, the turning point is "
         "visited before the end. The derivatives apply to one step. Many input changes within one step are therefore one move to the step's "
         "end, or two with a turning point.</p>\n<h2>State</h2>\n<p>fmi2GetFMUstate / fmi2SetFMUstate / fmi2SerializeFMUstate hold the memory "
         "(turning points), the input and the time; a serialized state names this FMU's GUID and is refused by an FMU of another table.</p>\n"
         "</body></html>\n";
}

const char* kLicence = "This FMU was written by hystlab " HYSTLAB_VERSION
                       ".\n\n"
                       "binaries/: the hystlab element runtime, built from the hystlab sources. It links the C++ standard library of the\n"
                       "system it was built on (libstdc++, GCC Runtime Library Exception).\n"
                       "resources/element.json: the calibrated data, measured or derived by the lab that exported it; its provenance is\n"
                       "inside the file. Ask that lab before passing it on.\n";
}  // namespace

std::string fmu_archive(std::string_view element_json, const FmuOptions& options) {
  const models::Element e = models::element_from_json(element_json);
  const std::string guid = element_guid(e.canonical_json);
  ZipWriter zip;
  zip.add("modelDescription.xml", model_description(e, guid, options));
  zip.add("binaries/linux64/" + std::string(kModelIdentifier) + ".so", fmu_runtime_binary(), 0755);
  zip.add("resources/element.json", e.canonical_json);
  zip.add("documentation/index.html", documentation(e, guid));
  zip.add("documentation/licenses/license.txt", kLicence);
  return zip.finish();
}

}  // namespace hystlab::fmu
