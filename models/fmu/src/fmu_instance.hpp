#pragma once
// One instance of the FMU: the calibrated element, its fixed parameters and its input, with the
// FMI 2.0 co-simulation modes. The C entry points (fmu_entry.cpp) check arguments, catch every
// exception and turn it into a status and a logged message; this class may throw FmuError.
#include <cmath>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "../fmi2_functions.h"
#include "hystlab/models/element.hpp"
#include "hystlab/models/preisach_model.hpp"

namespace hystlab::fmu {

struct FmuError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The resources folder of a file: URI (file:///a/b, file:/a/b, file://localhost/a/b) or a path.
[[nodiscard]] std::string resource_folder(const char* location);

class FmuInstance {
 public:
  enum class Mode { Instantiated, Initialization, Stepping, Terminated };

  // A saved state (fmi2GetFMUstate): everything a rolled-back step needs, and the parameter values
  // it was saved with (a state is only taken back under the same ones).
  struct Saved {
    std::unique_ptr<models::HysteresisModel> model;
    double time, x, committed, d1, d2;
    double x_scale, x_offset, force_scale;
    int sign;
  };

  FmuInstance(std::string name, std::string guid, const std::string& resources, const fmi2CallbackFunctions& callbacks, bool logging);

  void log(fmi2Status status, const char* category, const std::string& message) const;
  void set_logging(bool on) { logging_ = on; }
  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] Mode mode() const { return mode_; }
  [[nodiscard]] double time() const { return time_; }

  void setup(double start_time);
  void enter_initialization();
  void exit_initialization();
  void terminate() {
    if (mode_ == Mode::Instantiated) throw FmuError("the instance was never initialized (fmi2FreeInstance ends it)");
    mode_ = Mode::Terminated;
    refresh();
  }
  void reset();

  // The calls of every step, inline and without a lookup: false sends the caller to the checked
  // path (another variable, a non-finite value, a wrong mode), which says what is wrong.
  [[nodiscard]] bool try_set_input(fmi2ValueReference vr, double v) noexcept {
    if (vr != 0 || !std::isfinite(v) || mode_ == Mode::Terminated) return false;
    x_ = v;
    return true;
  }
  [[nodiscard]] bool try_get_force(fmi2ValueReference vr, double& out) const noexcept {
    if (vr != 1 || x_ != committed_x_) return false;
    out = force_;
    return true;
  }
  // A step of a held input (no derivatives set) in stepping mode; false: the checked do_step.
  [[nodiscard]] bool try_step(double t, double h) noexcept;

  void set_real(fmi2ValueReference vr, double v);
  void set_integer(fmi2ValueReference vr, int v);
  [[nodiscard]] double get_real(fmi2ValueReference vr) const;
  [[nodiscard]] int get_integer(fmi2ValueReference vr) const;
  void set_input_derivative(fmi2ValueReference vr, int order, double v);
  // The input over [t, t + h]: held, or the polynomial of its derivatives (docs/FORMATS.md "FMU").
  fmi2Status do_step(double t, double h);

  [[nodiscard]] Saved save() const;
  void restore(const Saved& s);
  // The states this instance handed out: an FMUstate is only ever one of these (a pointer from
  // elsewhere is refused by name, never dereferenced), and fmi2FreeInstance frees what is left.
  [[nodiscard]] Saved* keep(Saved s);
  [[nodiscard]] Saved& owned(const void* state) const;
  void release(const void* state);
  [[nodiscard]] std::vector<char> serialize(const Saved& s) const;
  [[nodiscard]] Saved deserialize(std::span<const char> bytes) const;

 private:
  [[nodiscard]] double to_mm(double x) const { return x * x_scale_ + x_offset_; }
  [[nodiscard]] double force(double model_force) const { return gain_ * model_force; }
  [[nodiscard]] double model_output() const noexcept { return table_ ? table_->output() : element_.model->output(); }
  // After any change of mode, parameters, derivatives or memory: the values the fast paths read.
  void refresh() noexcept {
    plain_ = mode_ == Mode::Stepping && d1_ == 0.0 && d2_ == 0.0;
    gain_ = static_cast<double>(sign_) * force_scale_;
    force_ = gain_ * model_output();
  }
  void require_parameters_settable(const char* name) const;
  void drive_to(double x_mm) noexcept;
  void warn_saturation(double x_mm) noexcept;

  std::string name_, guid_;
  fmi2CallbackFunctions callbacks_;
  bool logging_;
  models::Element element_;
  // The element's model when it is a table: PreisachModel is final, so a step through this
  // pointer is inlined here (bench_fmu: 282 instructions a step through the virtual call).
  models::PreisachModel* table_ = nullptr;
  Mode mode_ = Mode::Instantiated;
  double time_ = 0.0;
  double x_ = 0.0;              // the input as set (input units)
  double committed_x_ = 0.0;    // the input the model was last driven to (input units)
  double d1_ = 0.0, d2_ = 0.0;  // input derivatives for the next step (per s, per s^2)
  double x_scale_ = 1.0, x_offset_ = 0.0, force_scale_ = 1.0;
  int sign_ = 1;
  bool plain_ = false;  // stepping, no input derivatives: try_step may take the step
  double gain_ = 1.0;   // sign * force_scale
  double force_ = 0.0;  // F at the committed input
  bool warned_saturation_ = false;
  std::unordered_map<const void*, std::unique_ptr<Saved>> states_;
};

}  // namespace hystlab::fmu
