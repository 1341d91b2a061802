#include "hystlab/domain/events.hpp"

#include <stdexcept>
#include <type_traits>

namespace hystlab::domain {
namespace {
using nlohmann::json;

// A field of the wrong type: the message names it (decode_event adds the kind).
[[noreturn]] void wrong(const char* name, const char* want) { throw std::invalid_argument(std::string("field '") + name + "' must be " + want); }

template <class T>
struct is_optional : std::false_type {};
template <class T>
struct is_optional<std::optional<T>> : std::true_type {};

void put(json& j, const char* name, const json& v) { j[name] = v; }
template <class T>
void put(json& j, const char* name, const std::optional<T>& v) {
  if (v) j[name] = *v;  // absent, not null: "no such field" for this shape
}
template <class T>
requires(!is_optional<T>::value && !std::is_same_v<T, json>) void put(json& j, const char* name, const T& v) { j[name] = v; }

void read(const json& v, const char* name, double& out) {
  if (v.is_null()) {
    out = NAN;  // how a NaN is stored
    return;
  }
  if (!v.is_number()) wrong(name, "a number");
  out = v.get<double>();
}
template <class I>
requires std::is_integral_v<I> &&(!std::is_same_v<I, bool>)void read(const json& v, const char* name, I& out) {
  if (v.is_number_integer()) {
    out = v.get<I>();
    return;
  }
  if (v.is_number_float() && v.get<double>() == std::floor(v.get<double>()) && std::fabs(v.get<double>()) < 9e15) {
    out = static_cast<I>(v.get<double>());
    return;
  }
  wrong(name, "a whole number");
}
void read(const json& v, const char* name, bool& out) {
  if (!v.is_boolean()) wrong(name, "true or false");
  out = v.get<bool>();
}
void read(const json& v, const char* name, std::string& out) {
  if (!v.is_string()) wrong(name, "text");
  out = v.get<std::string>();
}
void read(const json& v, const char*, json& out) { out = v; }
template <class T>
void read(const json& v, const char* name, std::vector<T>& out) {
  if (!v.is_array()) wrong(name, "a list");
  out.assign(v.size(), T{});
  for (std::size_t i = 0; i < v.size(); ++i) read(v[i], name, out[i]);
}
void read(const json& v, const char* name, std::array<double, 2>& out) {
  if (!v.is_array() || v.size() != 2) wrong(name, "a pair of numbers");
  read(v[0], name, out[0]);
  read(v[1], name, out[1]);
}
template <class T>
void read(const json& v, const char* name, std::optional<T>& out) {
  T x{};
  read(v, name, x);
  out = std::move(x);
}

// A field missing keeps its default (an older detail).
template <class T>
void take(const json& j, const char* name, T& out) {
  const auto it = j.find(name);
  if (it != j.end()) read(*it, name, out);
}

template <class E>
struct Kind;  // the stored kind and fields of each event (HYSTLAB_EVENT below)

}  // namespace

// One line per kind: its stored name and its fields, in the order they are written.
#define HYSTLAB_PUT(f) put(j, #f, e.f);
#define HYSTLAB_TAKE(f) take(j, #f, e.f);
#define HYSTLAB_NAME(f) #f,
#define HYSTLAB_EVENT(Type, name, ...)                                                                                               \
  namespace {                                                                                                                        \
  template <>                                                                                                                        \
  struct Kind<Type> {                                                                                                                \
    static constexpr std::string_view kind = name;                                                                                   \
    static std::vector<std::string_view> fields() { return {NLOHMANN_JSON_EXPAND(NLOHMANN_JSON_PASTE(HYSTLAB_NAME, __VA_ARGS__))}; } \
    static void to(json& j, const Type& e) { NLOHMANN_JSON_EXPAND(NLOHMANN_JSON_PASTE(HYSTLAB_PUT, __VA_ARGS__)) }                   \
    static void from(const json& j, Type& e) { NLOHMANN_JSON_EXPAND(NLOHMANN_JSON_PASTE(HYSTLAB_TAKE, __VA_ARGS__)) }                \
  };                                                                                                                                 \
  }

HYSTLAB_EVENT(GapEvent, "gap", from_s, to_s, length_ms)
HYSTLAB_EVENT(GapsEvent, "gaps", count, total_ms, longest_ms)
HYSTLAB_EVENT(SafeEvent, "safe", position_mm, target_mm, seconds)
HYSTLAB_EVENT(LimitsEvent, "limits", displacement_mm, force_N, rate_mm_s, safe_position_mm, safe_rate_mm_s, in_position_mm)
HYSTLAB_EVENT(QualityEvent, "quality", run, samples, missed_deadlines, late_wakeups, dropped, lost_samples, io_errors, timeouts, reconnects, gaps, gap_total_s,
              longest_gap_s, rig_seconds, rate_hz, requested_rate_hz, time_scale, expected_rate_hz)
HYSTLAB_EVENT(ShakedownEvent, "shakedown", cycle, peak_force_N, energy_Nmm, consecutive, stable, damping_ratio, secant_stiffness_N_mm, peak_change_pct,
              energy_change_pct)
HYSTLAB_EVENT(TrainingEvent, "training", cycles, stable, until, why)
HYSTLAB_EVENT(ValidationEvent, "validation", run, reversals, seed, points_mm, why)
HYSTLAB_EVENT(RetakeEvent, "retake", rows, round, frequency_hz, attempt, why)
HYSTLAB_EVENT(DesignEvent, "design", rows, alpha_mm, estimated_rms_N, noise_N, spent_s, next_s, budget_s, target_rms_N, rig_s, why, stopped, nodes_mm)
HYSTLAB_EVENT(SineStepEvent, "sine_step", k, of, pass, passes, frequency_hz, amplitude_mm, direction, drive_mm, eta_s, change, shift_deg, glide_cycles)
HYSTLAB_EVENT(TransmissibilityEvent, "transmissibility", k, of, pass, frequency_hz, amplitude_mm, direction, drive_mm, base_amplitude_mm, base_phase_rad,
              mass_amplitude_mm, mass_phase_rad, ratio, phase_rad, thd, harmonics, control_error_pct, band, control_windows, settle_cycles, t_s, eta_s)
HYSTLAB_EVENT(SweepDoneEvent, "sweep_done", points, of, seconds, nominal_seconds, warnings, predicted_with)
HYSTLAB_EVENT(ControlAbortEvent, "control_abort", frequency_hz, demand_mm, base_mm, error_pct, drive_mm)
HYSTLAB_EVENT(ControlWarningEvent, "control_warning", frequency_hz, demand_mm, base_mm, error_pct, band)
HYSTLAB_EVENT(UnsettledEvent, "unsettled", frequency_hz, cycles, change_pct)
HYSTLAB_EVENT(PretestEvent, "pretest", frequencies, level_mm, windows, seconds, unsettled, response_min, response_max)
HYSTLAB_EVENT(DwellEvent, "dwell", pass, amplitude_mm, track, start_hz, frequency_hz, target_deg, phase_deg, cycles, windows, out_of_tolerance, locked)
HYSTLAB_EVENT(ResonanceUnresolvedEvent, "resonance_unresolved", pass, frequency_hz, amplitude_mm, band_points, wanted, added, why)
HYSTLAB_EVENT(FitEvent, "fit", nodes, required, accuracy)
HYSTLAB_EVENT(EnvelopeEvent, "envelope", stroke_mm, force_N, speed_mm_s, accel_mm_s2, displacement_mm, velocity_mm_s, accel_g, frequency_hz)
HYSTLAB_EVENT(RecordEvent, "record", specimen, notes)
HYSTLAB_EVENT(RecommendationEvent, "recommendation", table, method, n, why)

namespace {
// "while" is a C++ keyword: this kind is written out by hand.
template <>
struct Kind<ControlUnreachedEvent> {
  static constexpr std::string_view kind = "control_unreached";
  static std::vector<std::string_view> fields() { return {"frequency_hz", "demand_mm", "error_pct", "windows", "drive_mm", "limited", "while"}; }
  static void to(json& j, const ControlUnreachedEvent& e) {
    put(j, "frequency_hz", e.frequency_hz), put(j, "demand_mm", e.demand_mm), put(j, "error_pct", e.error_pct);
    put(j, "windows", e.windows), put(j, "drive_mm", e.drive_mm), put(j, "limited", e.limited), put(j, "while", e.while_);
  }
  static void from(const json& j, ControlUnreachedEvent& e) {
    take(j, "frequency_hz", e.frequency_hz), take(j, "demand_mm", e.demand_mm), take(j, "error_pct", e.error_pct);
    take(j, "windows", e.windows), take(j, "drive_mm", e.drive_mm), take(j, "limited", e.limited), take(j, "while", e.while_);
  }
};
// Plain text, as the daemon has always stored it.
template <>
struct Kind<CommandEvent> {
  static constexpr std::string_view kind = "command";
  static std::vector<std::string_view> fields() { return {}; }
};

template <class E>
json object_of(const E& e) {
  json j = json::object();
  Kind<E>::to(j, e);
  return j;
}

// Each alternative's index, found once: decode_event looks the kind up here.
template <std::size_t... I>
std::optional<CampaignEvent> make(std::string_view kind, std::index_sequence<I...>) {
  std::optional<CampaignEvent> out;
  ((Kind<std::variant_alternative_t<I, CampaignEvent>>::kind == kind ? (void)out.emplace(std::in_place_index<I>) : (void)0), ...);
  return out;
}
}  // namespace

std::string_view kind_of(const CampaignEvent& e) noexcept {
  return std::visit([](const auto& x) { return Kind<std::decay_t<decltype(x)>>::kind; }, e);
}

json detail_json(const CampaignEvent& e) {
  return std::visit(
      [](const auto& x) -> json {
        using E = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<E, CommandEvent>)
          return x.text;
        else
          return object_of(x);
      },
      e);
}

std::string encode(const CampaignEvent& e) {
  if (const auto* c = std::get_if<CommandEvent>(&e)) return c->text;
  // Text that is not UTF-8 (a specimen's name typed in another encoding) is replaced, not thrown on.
  return detail_json(e).dump(-1, ' ', false, json::error_handler_t::replace);
}

std::optional<CampaignEvent> decode_event(std::string_view kind, std::string_view detail, std::string& error) {
  error.clear();
  std::optional<CampaignEvent> out = make(kind, std::make_index_sequence<std::variant_size_v<CampaignEvent>>{});
  if (!out) return std::nullopt;
  if (auto* c = std::get_if<CommandEvent>(&*out)) {
    c->text = std::string(detail);
    return out;
  }
  const json j = json::parse(detail.empty() ? std::string_view("{}") : detail, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    error = std::string(kind) + ": its detail is not a JSON object";
    return std::nullopt;
  }
  try {
    std::visit(
        [&j](auto& x) {
          using E = std::decay_t<decltype(x)>;
          if constexpr (!std::is_same_v<E, CommandEvent>) Kind<E>::from(j, x);
        },
        *out);
  } catch (const std::exception& ex) {
    error = std::string(kind) + ": " + ex.what();
    return std::nullopt;
  }
  return out;
}

namespace {
template <std::size_t... I>
std::vector<EventKind> all_kinds(std::index_sequence<I...>) {
  return {EventKind{Kind<std::variant_alternative_t<I, CampaignEvent>>::kind, Kind<std::variant_alternative_t<I, CampaignEvent>>::fields()}...};
}
}  // namespace

const std::vector<EventKind>& event_kinds() {
  static const std::vector<EventKind> kinds = all_kinds(std::make_index_sequence<std::variant_size_v<CampaignEvent>>{});
  return kinds;
}

}  // namespace hystlab::domain
