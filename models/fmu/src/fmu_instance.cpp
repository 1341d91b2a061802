#include "fmu_instance.hpp"

#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "fmu_guid.hpp"
#include "fmu_state.hpp"
#include "fmu_variables.hpp"
#include "hystlab/models/text_forms.hpp"

namespace hystlab::fmu {
namespace {
// The input the model was driven to, before it was: F is then read at the input as set (peek), so
// it already follows x and the parameters in initialization mode.
constexpr double kNotDriven = std::numeric_limits<double>::quiet_NaN();
constexpr std::size_t kInstanceNumbers = 9;  // time, x, committed, d1, d2, x_scale, x_offset, force_scale, sign

std::string text(double v) { return models::exact_text(v); }

std::string percent_decoded(const std::string& s) {
  std::string out;
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (s[k] == '%' && k + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[k + 1])) && std::isxdigit(static_cast<unsigned char>(s[k + 2]))) {
      out.push_back(static_cast<char>(std::stoi(s.substr(k + 1, 2), nullptr, 16)));
      k += 2;
    } else {
      out.push_back(s[k]);
    }
  }
  return out;
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FmuError("cannot read the FMU's resource '" + path + "' (is the FMU unpacked whole?)");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The step of a table with everything it calls inlined: GCC 12 at -O2 kept PreisachModel::advance
// and EverettTable::value_in_range out of line here (bench_fmu: 280 instructions a step, against
// 141 for the C API's step of the same table).
[[gnu::flatten]] void table_step(models::PreisachModel& m, double x_mm) noexcept { (void)m.step(x_mm); }

const Variable& variable(fmi2ValueReference vr, VarType type) {
  for (const Variable& v : kVariables)
    if (v.vr == vr && v.type == type) return v;
  throw FmuError("no " + std::string(type == VarType::Real ? "Real" : "Integer") + " variable has value reference " + std::to_string(vr));
}
}  // namespace

std::string resource_folder(const char* location) {
  if (!location || !*location) throw FmuError("no resource location was given (fmuResourceLocation is empty)");
  std::string s = location;
  if (s.rfind("file://localhost/", 0) == 0)
    s = s.substr(16);
  else if (s.rfind("file:///", 0) == 0)
    s = s.substr(7);
  else if (s.rfind("file:/", 0) == 0)
    s = s.substr(5);
  else if (s.find("://") != std::string::npos)
    throw FmuError("resource location '" + std::string(location) + "' is not a file: URI");
  s = percent_decoded(s);
  while (s.size() > 1 && s.back() == '/') s.pop_back();
  return s;
}

FmuInstance::FmuInstance(std::string name, std::string guid, const std::string& resources, const fmi2CallbackFunctions& callbacks, bool logging)
    : name_(std::move(name)), guid_(std::move(guid)), callbacks_(callbacks), logging_(logging) {
  const std::string doc = read_all(resources + "/element.json");
  const std::string own = element_guid(doc);
  if (own != guid_) throw FmuError("GUID " + guid_ + " does not match the FMU's resources (" + own + "): binary and resources from different FMUs");
  element_ = models::element_from_json(doc);
  table_ = dynamic_cast<models::PreisachModel*>(element_.model.get());
  x_ = element_.rest_input_mm;
  committed_x_ = kNotDriven;
  refresh();
}

void FmuInstance::log(fmi2Status status, const char* category, const std::string& message) const {
  if (!callbacks_.logger || (status == fmi2OK && !logging_)) return;
  callbacks_.logger(callbacks_.componentEnvironment, name_.c_str(), status, category, "%s", message.c_str());
}

void FmuInstance::setup(double start_time) {
  if (mode_ != Mode::Instantiated) throw FmuError("only before initialization");
  if (!std::isfinite(start_time)) throw FmuError("startTime is not a finite number");
  time_ = start_time;
}

void FmuInstance::enter_initialization() {
  if (mode_ != Mode::Instantiated) throw FmuError("the instance is not freshly instantiated (call fmi2Reset)");
  mode_ = Mode::Initialization;
}

// The parameters are checked as a set (x_scale_mm non-zero), then the element is driven to the input.
void FmuInstance::exit_initialization() {
  if (mode_ != Mode::Initialization) throw FmuError("not in initialization mode");
  if (x_scale_ == 0.0) throw FmuError("x_scale_mm: 0 would make every input the same displacement");
  drive_to(to_mm(x_));
  committed_x_ = x_;
  mode_ = Mode::Stepping;
  refresh();
}

void FmuInstance::reset() {
  element_.model->reset();
  mode_ = Mode::Instantiated;
  time_ = d1_ = d2_ = x_offset_ = 0.0;
  x_ = element_.rest_input_mm;
  committed_x_ = kNotDriven;
  x_scale_ = force_scale_ = 1.0;
  sign_ = 1;
  warned_saturation_ = false;
  refresh();
}

void FmuInstance::require_parameters_settable(const char* name) const {
  if (mode_ != Mode::Instantiated && mode_ != Mode::Initialization)
    throw FmuError(std::string(name) + ": a fixed parameter, set only before fmi2ExitInitializationMode");
}

void FmuInstance::set_real(fmi2ValueReference vr, double v) {
  if (vr == kX && std::isfinite(v) && mode_ != Mode::Terminated) [[likely]] {  // every step's call: no lookup
    x_ = v;
    return;
  }
  const Variable& var = variable(vr, VarType::Real);
  if (mode_ == Mode::Terminated) throw FmuError(std::string(var.name) + ": the instance is terminated");
  if (!std::isfinite(v)) throw FmuError(std::string(var.name) + ": " + text(v) + " is not a finite number");
  switch (vr) {
    case kX:
      x_ = v;
      return;
    case kXScale:
      require_parameters_settable("x_scale_mm"), x_scale_ = v;
      return;
    case kXOffset:
      require_parameters_settable("x_offset_mm"), x_offset_ = v;
      return;
    case kForceScale:
      require_parameters_settable("force_scale"), force_scale_ = v, refresh();
      return;
    default:
      throw FmuError(std::string(var.name) + " is an output: it cannot be set");
  }
}

void FmuInstance::set_integer(fmi2ValueReference vr, int v) {
  const Variable& var = variable(vr, VarType::Integer);
  if (vr != kSign) throw FmuError(std::string(var.name) + " is an output: it cannot be set");
  require_parameters_settable("sign");
  if (v != 1 && v != -1) throw FmuError("sign: " + std::to_string(v) + " is not +1 or -1");
  sign_ = v;
  refresh();
}

double FmuInstance::get_real(fmi2ValueReference vr) const {
  if (vr == kF && x_ == committed_x_) [[likely]]  // every step's call, after fmi2DoStep
    return force(element_.model->output());
  (void)variable(vr, VarType::Real);
  switch (vr) {
    case kX:
      return x_;
    case kXScale:
      return x_scale_;
    case kXOffset:
      return x_offset_;
    case kForceScale:
      return force_scale_;
    default:  // F: direct feedthrough; an input set since the last step is read without being taken
      return force(x_ == committed_x_ ? element_.model->output() : element_.model->peek(to_mm(x_)));
  }
}

int FmuInstance::get_integer(fmi2ValueReference vr) const {
  (void)variable(vr, VarType::Integer);
  if (vr == kSign) return sign_;
  const auto n = element_.model->saturation_count();
  return n > static_cast<std::uint64_t>(INT_MAX) ? INT_MAX : static_cast<int>(n);
}

void FmuInstance::set_input_derivative(fmi2ValueReference vr, int order, double v) {
  if (mode_ != Mode::Initialization && mode_ != Mode::Stepping) throw FmuError("input derivatives: only in initialization mode or between steps");
  if (vr != kX) throw FmuError("input derivatives: value reference " + std::to_string(vr) + " is not the input x");
  if (order != 1 && order != 2) throw FmuError("input derivatives: order " + std::to_string(order) + " (this FMU takes orders 1 and 2)");
  if (!std::isfinite(v)) throw FmuError("input derivatives: " + text(v) + " is not a finite number");
  (order == 1 ? d1_ : d2_) = v;
  refresh();
}

void FmuInstance::drive_to(double x_mm) noexcept {
  if (!table_) {
    (void)element_.model->step(x_mm);  // the simplified model has no range to leave
    return;
  }
  const auto before = table_->saturation_count();
  table_step(*table_, x_mm);
  if (table_->saturation_count() != before && !warned_saturation_) [[unlikely]]
    warn_saturation(x_mm);
}

[[gnu::cold, gnu::noinline]] void FmuInstance::warn_saturation(double x_mm) noexcept {
  warned_saturation_ = true;
  try {
    log(fmi2Warning, "logStatusWarning",
        "x = " + text(x_mm) + " mm is outside the table's range [" + text(element_.lo_mm) + ", " + text(element_.hi_mm) +
            "] mm: clamped (every such input is counted in the output 'saturations'; this is said once)");
  } catch (...) {  // out of memory for the message: the count in 'saturations' still says it
  }
}

// Every call inlined (the table's step among them): the step an importer makes per input.
[[gnu::flatten]] bool FmuInstance::try_step(double t, double h) noexcept {
  const double mm = to_mm(x_);
  if (!plain_ || !(h > 0.0 && h < 1e300) || !(t > -1e300 && t < 1e300) || !(mm > -1e300 && mm < 1e300)) return false;
  drive_to(mm);
  committed_x_ = x_;
  time_ = t + h;
  force_ = gain_ * model_output();
  return true;
}

// Rate-independent: the force at the step's end depends on the path only through its extremes.
// A held input (or a linear one) is a single move to the end; a quadratic one may turn inside the
// step, and then the turning point is visited first.
fmi2Status FmuInstance::do_step(double t, double h) {
  if (mode_ != Mode::Stepping) throw FmuError("the instance is not initialized (or is terminated)");
  if (!(h > 0.0) || !std::isfinite(h) || !std::isfinite(t)) throw FmuError("communicationStepSize " + text(h) + " is not a positive finite number");
  // Both points in mm, checked, before the memory moves: a refused step leaves the instance as it was.
  double turn_mm = std::numeric_limits<double>::quiet_NaN();
  if (d2_ != 0.0) {
    const double tau = -d1_ / d2_;
    if (tau > 0.0 && tau < h) turn_mm = to_mm(x_ + d1_ * tau + 0.5 * d2_ * tau * tau);
  }
  const double end = (d1_ == 0.0 && d2_ == 0.0) ? x_ : x_ + d1_ * h + 0.5 * d2_ * h * h;
  if (!std::isfinite(end) || !std::isfinite(to_mm(end)) || (!std::isnan(turn_mm) && !std::isfinite(turn_mm)))
    throw FmuError("the input (with its derivatives, scale and offset) goes beyond a finite number within the step");
  if (!std::isnan(turn_mm)) drive_to(turn_mm);
  drive_to(to_mm(end));
  x_ = committed_x_ = end;
  d1_ = d2_ = 0.0;
  time_ = t + h;
  refresh();
  return fmi2OK;
}

FmuInstance::Saved FmuInstance::save() const {
  return Saved{element_.model->clone(), time_, x_, committed_x_, d1_, d2_, x_scale_, x_offset_, force_scale_, sign_};
}

void FmuInstance::restore(const Saved& s) {
  if (s.x_scale != x_scale_ || s.x_offset != x_offset_ || s.force_scale != force_scale_ || s.sign != sign_)
    throw FmuError("the state was saved with other parameter values (x_scale_mm " + text(s.x_scale) + ", x_offset_mm " + text(s.x_offset) + ", force_scale " +
                   text(s.force_scale) + ", sign " + std::to_string(s.sign) + ") than this instance's");
  element_.model = s.model->clone();
  table_ = dynamic_cast<models::PreisachModel*>(element_.model.get());
  time_ = s.time;
  x_ = s.x;
  committed_x_ = s.committed;
  d1_ = s.d1;
  d2_ = s.d2;
  refresh();
}

FmuInstance::Saved* FmuInstance::keep(Saved s) {
  auto p = std::make_unique<Saved>(std::move(s));
  Saved* raw = p.get();
  states_.emplace(raw, std::move(p));
  return raw;
}

FmuInstance::Saved& FmuInstance::owned(const void* state) const {
  const auto it = states_.find(state);
  if (it == states_.end()) throw FmuError("the FMUstate was not got from this instance (or is already freed)");
  return *it->second;
}

void FmuInstance::release(const void* state) {
  if (states_.erase(state) == 0) throw FmuError("the FMUstate was not got from this instance (or is already freed)");
}

std::vector<char> FmuInstance::serialize(const Saved& s) const {
  StateRecord r{guid_, {s.time, s.x, s.committed, s.d1, s.d2, s.x_scale, s.x_offset, s.force_scale, static_cast<double>(s.sign)}};
  const std::vector<double> m = s.model->save_state();
  r.numbers.insert(r.numbers.end(), m.begin(), m.end());
  return encode_state(r);
}

FmuInstance::Saved FmuInstance::deserialize(std::span<const char> bytes) const {
  StateRecord r;
  try {
    r = decode_state(bytes);
  } catch (const std::invalid_argument& e) {
    throw FmuError(e.what());
  }
  if (r.guid != guid_)
    throw FmuError("FMU state: saved by another FMU (GUID " + r.guid + "; this one is " + guid_ + "): a state belongs to the table it was saved from");
  if (r.numbers.size() < kInstanceNumbers) throw FmuError("FMU state: " + std::to_string(r.numbers.size()) + " numbers, too few for a state");
  const double* n = r.numbers.data();
  for (std::size_t k = 0; k < kInstanceNumbers; ++k)  // the input taken is NaN before initialization ends
    if (!std::isfinite(n[k]) && !(k == 2 && std::isnan(n[k]))) throw FmuError("FMU state: value " + std::to_string(k) + " is not a finite number");
  if (n[5] != x_scale_ || n[6] != x_offset_ || n[7] != force_scale_ || n[8] != static_cast<double>(sign_))
    throw FmuError("FMU state: saved with other parameter values (x_scale_mm " + text(n[5]) + ", x_offset_mm " + text(n[6]) + ", force_scale " + text(n[7]) +
                   ", sign " + text(n[8]) + ") than this instance's");
  Saved s{element_.model->clone(), n[0], n[1], n[2], n[3], n[4], n[5], n[6], n[7], sign_};
  try {
    s.model->restore_state(std::span<const double>(r.numbers).subspan(kInstanceNumbers));
  } catch (const std::invalid_argument& e) {
    throw FmuError(e.what());
  }
  return s;
}

}  // namespace hystlab::fmu
