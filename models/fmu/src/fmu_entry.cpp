// The FMI 2.0 co-simulation entry points: arguments checked, every exception caught and turned
// into a status with a logged message naming the problem. Nothing here may take the importer down.
#include <cstring>
#include <new>
#include <string>

#include "../fmi2_functions.h"
#include "fmu_instance.hpp"

using hystlab::fmu::FmuError;
using hystlab::fmu::FmuInstance;

namespace {
FmuInstance* inst(fmi2Component c) { return static_cast<FmuInstance*>(c); }

template <class F>
fmi2Status guard(fmi2Component c, const char* call, F&& f) noexcept {
  if (!c) return fmi2Error;
  try {
    return f(*inst(c));
  } catch (const std::bad_alloc&) {
    inst(c)->log(fmi2Fatal, "logStatusFatal", std::string(call) + ": out of memory");
    return fmi2Fatal;
  } catch (const std::exception& e) {
    inst(c)->log(fmi2Error, "logStatusError", std::string(call) + ": " + e.what());
    return fmi2Error;
  }
}

bool arrays_ok(FmuInstance& i, const char* call, size_t n, const void* a, const void* b) {
  if (n == 0 || (a && b)) return true;
  i.log(fmi2Error, "logStatusError", std::string(call) + ": a null array");
  return false;
}

// The checked paths of the calls every step makes: out of line, so the fast paths stay small.
[[gnu::noinline]] fmi2Status do_step_checked(fmi2Component c, double t, double h) {
  return guard(c, "fmi2DoStep", [&](FmuInstance& i) { return i.do_step(t, h); });
}

[[gnu::noinline]] fmi2Status get_real_checked(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]) {
  return guard(c, "fmi2GetReal", [&](FmuInstance& i) {
    if (!arrays_ok(i, "fmi2GetReal", n, vr, v)) return fmi2Error;
    for (size_t k = 0; k < n; ++k) v[k] = i.get_real(vr[k]);
    return fmi2OK;
  });
}
[[gnu::noinline]] fmi2Status set_real_checked(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]) {
  return guard(c, "fmi2SetReal", [&](FmuInstance& i) {
    if (!arrays_ok(i, "fmi2SetReal", n, vr, v)) return fmi2Error;
    for (size_t k = 0; k < n; ++k) i.set_real(vr[k], v[k]);
    return fmi2OK;
  });
}

fmi2Status not_provided(fmi2Component c, const char* what) {
  return guard(c, what, [&](FmuInstance&) -> fmi2Status { throw FmuError("not provided by this FMU (see modelDescription.xml)"); });
}
}  // namespace

extern "C" {

const char* fmi2GetTypesPlatform(void) { return "default"; }
const char* fmi2GetVersion(void) { return "2.0"; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t, const fmi2String[]) {
  return guard(c, "fmi2SetDebugLogging", [&](FmuInstance& i) { return i.set_logging(on != fmi2False), fmi2OK; });
}
fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources, const fmi2CallbackFunctions* functions, fmi2Boolean,
                              fmi2Boolean logging) {
  fmi2CallbackFunctions cb{};
  if (functions) cb = *functions;
  const std::string who = name ? name : "";
  auto say = [&](const std::string& m) {
    if (cb.logger) cb.logger(cb.componentEnvironment, who.c_str(), fmi2Error, "logStatusError", "%s", m.c_str());
  };
  try {
    if (type != fmi2CoSimulation) throw FmuError("this FMU is for co-simulation only (fmuType is not fmi2CoSimulation)");
    if (!guid) throw FmuError("no GUID was given");
    return new FmuInstance(who, guid, hystlab::fmu::resource_folder(resources), cb, logging != fmi2False);
  } catch (const std::exception& e) {
    say(std::string("fmi2Instantiate: ") + e.what());
    return nullptr;
  }
}

void fmi2FreeInstance(fmi2Component c) { delete inst(c); }

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean, fmi2Real, fmi2Real start, fmi2Boolean, fmi2Real) {
  return guard(c, "fmi2SetupExperiment", [&](FmuInstance& i) { return i.setup(start), fmi2OK; });
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
  return guard(c, "fmi2EnterInitializationMode", [&](FmuInstance& i) { return i.enter_initialization(), fmi2OK; });
}
fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
  return guard(c, "fmi2ExitInitializationMode", [&](FmuInstance& i) { return i.exit_initialization(), fmi2OK; });
}
fmi2Status fmi2Terminate(fmi2Component c) {
  return guard(c, "fmi2Terminate", [&](FmuInstance& i) { return i.terminate(), fmi2OK; });
}
fmi2Status fmi2Reset(fmi2Component c) {
  return guard(c, "fmi2Reset", [&](FmuInstance& i) { return i.reset(), fmi2OK; });
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]) {
  if (c && n == 1 && vr && v && inst(c)->try_get_force(vr[0], v[0])) [[likely]]
    return fmi2OK;
  return get_real_checked(c, vr, n, v);
}
fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
  return guard(c, "fmi2GetInteger", [&](FmuInstance& i) {
    if (!arrays_ok(i, "fmi2GetInteger", n, vr, v)) return fmi2Error;
    for (size_t k = 0; k < n; ++k) v[k] = i.get_integer(vr[k]);
    return fmi2OK;
  });
}
fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]) {
  if (c && n == 1 && vr && v && inst(c)->try_set_input(vr[0], v[0])) [[likely]]
    return fmi2OK;
  return set_real_checked(c, vr, n, v);
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) {
  return guard(c, "fmi2SetInteger", [&](FmuInstance& i) {
    if (!arrays_ok(i, "fmi2SetInteger", n, vr, v)) return fmi2Error;
    for (size_t k = 0; k < n; ++k) i.set_integer(vr[k], v[k]);
    return fmi2OK;
  });
}
// No Boolean or String variables: any value reference is unknown, none is fine.
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference[], size_t n, fmi2Boolean[]) {
  return n == 0 ? (c ? fmi2OK : fmi2Error) : not_provided(c, "fmi2GetBoolean (no Boolean variables)");
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference[], size_t n, fmi2String[]) {
  return n == 0 ? (c ? fmi2OK : fmi2Error) : not_provided(c, "fmi2GetString (no String variables)");
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference[], size_t n, const fmi2Boolean[]) {
  return n == 0 ? (c ? fmi2OK : fmi2Error) : not_provided(c, "fmi2SetBoolean (no Boolean variables)");
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference[], size_t n, const fmi2String[]) {
  return n == 0 ? (c ? fmi2OK : fmi2Error) : not_provided(c, "fmi2SetString (no String variables)");
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate* s) {
  return guard(c, "fmi2GetFMUstate", [&](FmuInstance& i) {
    if (!s) throw FmuError("a null FMUstate pointer");
    if (*s)
      i.owned(*s) = i.save();  // a state this instance gave, to be overwritten
    else
      *s = i.keep(i.save());
    return fmi2OK;
  });
}
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) {
  return guard(c, "fmi2SetFMUstate", [&](FmuInstance& i) {
    if (!s) throw FmuError("a null FMUstate");
    i.restore(i.owned(s));
    return fmi2OK;
  });
}
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate* s) {
  return guard(c, "fmi2FreeFMUstate", [&](FmuInstance& i) {
    if (s && *s) i.release(*s), *s = nullptr;
    return fmi2OK;
  });
}
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t* size) {
  return guard(c, "fmi2SerializedFMUstateSize", [&](FmuInstance& i) {
    if (!s || !size) throw FmuError("a null FMUstate or size");
    *size = i.serialize(i.owned(s)).size();
    return fmi2OK;
  });
}
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte bytes[], size_t size) {
  return guard(c, "fmi2SerializeFMUstate", [&](FmuInstance& i) {
    if (!s || !bytes) throw FmuError("a null FMUstate or buffer");
    const std::vector<char> b = i.serialize(i.owned(s));
    if (size < b.size()) throw FmuError("the buffer holds " + std::to_string(size) + " bytes; the state needs " + std::to_string(b.size()));
    std::memcpy(bytes, b.data(), b.size());
    return fmi2OK;
  });
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate* s) {
  return guard(c, "fmi2DeSerializeFMUstate", [&](FmuInstance& i) {
    if (!s || (!bytes && size > 0)) throw FmuError("a null buffer or FMUstate pointer");
    *s = i.keep(i.deserialize(std::span<const char>(bytes, size)));  // *s is output only: never read
    return fmi2OK;
  });
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference[], size_t, const fmi2ValueReference[], size_t, const fmi2Real[], fmi2Real[]) {
  return not_provided(c, "fmi2GetDirectionalDerivative");
}
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer order[], const fmi2Real v[]) {
  return guard(c, "fmi2SetRealInputDerivatives", [&](FmuInstance& i) {
    if (!arrays_ok(i, "fmi2SetRealInputDerivatives", n, vr, v) || (n > 0 && !order)) return fmi2Error;
    for (size_t k = 0; k < n; ++k) i.set_input_derivative(vr[k], order[k], v[k]);
    return fmi2OK;
  });
}
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference[], size_t, const fmi2Integer[], fmi2Real[]) {
  return not_provided(c, "fmi2GetRealOutputDerivatives (maxOutputDerivativeOrder is 0)");
}
fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean) {
  if (c && inst(c)->try_step(t, h)) [[likely]]
    return fmi2OK;
  return do_step_checked(c, t, h);
}
fmi2Status fmi2CancelStep(fmi2Component c) { return not_provided(c, "fmi2CancelStep (doStep never runs asynchronously)"); }
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind, fmi2Status*) { return not_provided(c, "fmi2GetStatus (doStep never returns fmi2Pending)"); }
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Real* v) {
  return guard(c, "fmi2GetRealStatus", [&](FmuInstance& i) {
    if (kind != fmi2LastSuccessfulTime || !v) throw FmuError("only fmi2LastSuccessfulTime is provided");
    *v = i.time();
    return fmi2OK;
  });
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind, fmi2Integer*) { return not_provided(c, "fmi2GetIntegerStatus"); }
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Boolean* v) {
  return guard(c, "fmi2GetBooleanStatus", [&](FmuInstance& i) {
    if (kind != fmi2Terminated || !v) throw FmuError("only fmi2Terminated is provided");
    *v = i.mode() == FmuInstance::Mode::Terminated ? fmi2True : fmi2False;
    return fmi2OK;
  });
}
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind, fmi2String*) { return not_provided(c, "fmi2GetStringStatus"); }

}  // extern "C"
