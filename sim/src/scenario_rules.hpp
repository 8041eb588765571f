#pragma once
// The scenario reader's rules that the reader (scenario.cpp) and the struct's setter
// (scenario_set.cpp) share: one place each.

#include <functional>
#include <set>
#include <string>
#include <vector>

#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::sim::detail {

/// The scenario gives `key` (a map or a value; Scenario::given_keys).
inline bool gives(const Scenario& s, const std::string& key) { return s.given_keys.count(key) > 0; }

/// A controller's nominal model by default: the plant itself, without the effects it does not know.
plant::PlantParams model_of_plant(const plant::PlantParams& plant);

/// The name goes into plot titles, summary.json and messages: printable UTF-8 of bounded length.
void check_name(const std::string& name, const std::string& what);

/// output.columns known and each once (output.every >= 1 is its list's range); `columns_given`: an empty list is an
/// error.
void check_output(const OutputConfig& out, bool columns_given);

/// control_period <= duration and the run's step count within kMaxSteps; the messages quote
/// `duration` and `period` (the values as written, or their shortest text).
void check_timing(const Scenario& s, const std::string& duration, const std::string& period);

/// A file name of the scenario resolved against its folder (an absolute one as it is).
std::string resolved_file(const std::string& base_dir, const std::string& file);

/// controller.library as the plugin host opens it: resolved against the scenario's folder, normalised.
std::string plugin_library(const std::string& base_dir, const std::string& file);

/// A plugin parameter's name: letters, digits and _ only.
bool parameter_name(const std::string& key);

/// The keys of the cascade's list a tuning does not take: under `rule` the gains kp, kv, ki (the
/// rule sets them, controller::apply_tuning), under `manual` bandwidth_scale (a factor of the rule).
const std::set<std::string>& keys_not_taken(controller::CascadeTuning t);

/// Throws ScenarioError "controller.kp: set by tuning: rule (remove it, or use tuning: manual)" or
/// "controller.bandwidth_scale: only with tuning: rule" for a key `given` says is given that the
/// tuning does not take.
void check_cascade_tuning(controller::CascadeTuning t, const std::function<bool(const std::string&)>& given);

/// Calls f(params) with the params struct of the reference's type `t` (sine, step, accel_limited,
/// scurve, ramp): the one mapping from a reference type to its list. none and waypoints have no
/// list (f is not called; the waypoints' file is a rule of its own).
template <typename C, typename F>
void with_reference_params(C& c, ReferenceType t, F&& f) {
  switch (t) {
    case ReferenceType::kSine: return f(c.sine);
    case ReferenceType::kStep: return f(c.step);
    case ReferenceType::kAccelLimited: return f(c.accel_limited);
    case ReferenceType::kSCurve: return f(c.scurve);
    case ReferenceType::kRamp: return f(c.ramp);
    case ReferenceType::kNone:
    case ReferenceType::kWaypoints: return;
  }
}

/// Calls f(params) with the params struct of the controller's type `t` (sliding_mode, cascade,
/// open_loop, plugin): the one mapping from a controller type to its list.
template <typename C, typename F>
void with_controller_params(C& cc, ControllerType t, F&& f) {
  switch (t) {
    case ControllerType::kSlidingMode: return f(cc.sliding_mode);
    case ControllerType::kCascade: return f(cc.cascade);
    case ControllerType::kOpenLoop: return f(cc.open_loop);
    case ControllerType::kPlugin: return f(cc.plugin);
  }
}

/// derive() and the whole-scenario checks of parse_scenario (each component's validate(), the
/// files it names, the functions of time, the warnings) on a scenario as read.
void derive_and_check(Scenario& s);

}  // namespace feeddrive::sim::detail
