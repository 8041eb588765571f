#include "feeddrive/sim/summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <utility>

namespace feeddrive::sim {

OutputLimits controller_output_limits(const Scenario& s) {
  const ControllerConfig& c = s.controller;
  switch (c.type) {
    case ControllerType::kSlidingMode: return {c.sliding_mode.u_min, c.sliding_mode.u_max};
    case ControllerType::kCascade: return {c.cascade.u_min, c.cascade.u_max};
    case ControllerType::kOpenLoop: return {c.open_loop.u_min, c.open_loop.u_max};
    case ControllerType::kPlugin: return {c.plugin.u_min, c.plugin.u_max};
  }
  return {};
}

double controller_output_range(const Scenario& s) {
  const OutputLimits l = controller_output_limits(s);
  return l.u_max - l.u_min;
}

std::string controller_model_source(const Scenario& s) {
  if (s.controller.type == ControllerType::kOpenLoop) return "";
  if (s.controller.model_given) return "own";
  return s.plant.effects.any() ? "plant_without_effects" : "plant";
}

SummaryBuilder::SummaryBuilder(const Scenario& s)
    : settled_after_(s.analysis.settled_after), control_period_(s.control_period) {
  m_.settled_after_s = settled_after_;
  // A rest-to-rest move: a reference with a finite end (summary.hpp, "Move metrics").
  const ReferenceType type = s.reference.type;
  if (type == ReferenceType::kStep || type == ReferenceType::kAccelLimited || type == ReferenceType::kSCurve ||
      type == ReferenceType::kWaypoints) {
    const auto ref = make_reference(s);
    move_end_ = ref->end_time();
    is_move_ = std::isfinite(move_end_);
    x0_ = ref->sample(0.0).position;
    target_ = ref->sample(is_move_ ? move_end_ : 0.0).position;
    distance_ = target_ - x0_;
    band_ = s.analysis.settling_band > 0.0 ? s.analysis.settling_band : 0.02 * std::abs(distance_);
  }
  chatter_delta_ = 0.01 * controller_output_range(s);
  m_.control_chatter_threshold_V = chatter_delta_;
  direction_band_ = 0.001 * controller_output_range(s);
  m_.control_direction_band_V = direction_band_;
  thrust_gain_ = s.plant.thrust_gain();
  m_.force_hf_limit_N = kSignalLimits.force_hf_rms_deltas * thrust_gain_ * chatter_delta_;
  // 2nd-order Butterworth high-pass at f_c, bilinear with pre-warping: K = tan(pi f_c T),
  // H(z) = (1 - 2z^-1 + z^-2) / ((1 + sqrt2 K + K^2) + 2(K^2 - 1) z^-1 + (1 - sqrt2 K + K^2) z^-2)
  // (e.g. R. Bristow-Johnson, "Audio EQ cookbook", HPF with Q = 1/sqrt2); |H| at f is the analog
  // prototype's at the warped frequency tan(pi f T)/K: (w^2)/sqrt(1 + w^4).
  const double fc = kSignalLimits.hf_corner_hz;
  m_.force_hf_corner_Hz = fc;
  hf_defined_ = control_period_ > 0.0 && fc < 0.5 / control_period_;
  if (hf_defined_) {
    const double k = std::tan(3.14159265358979323846 * fc * control_period_);
    const double norm = 1.0 / (1.0 + std::sqrt(2.0) * k + k * k);
    hb0_ = norm;
    ha1_ = 2.0 * (k * k - 1.0) * norm;
    ha2_ = (1.0 - std::sqrt(2.0) * k + k * k) * norm;
  }
}

namespace {
// A difference of two finite doubles can exceed the largest double (1e308 - -1e308): the metrics
// saturate there instead of becoming infinite (NaN, a run without truth, stays NaN).
constexpr double kLargest = std::numeric_limits<double>::max();
// The move metrics' keys in summary.json, in order (null where they do not apply).
const std::pair<const char*, double Summary::*> kMoveFields[] = {
    {"move_start_s", &Summary::move_start_s},
    {"move_end_s", &Summary::move_end_s},
    {"move_distance_m", &Summary::move_distance_m},
    {"rise_time_s", &Summary::rise_time_s},
    {"overshoot_m", &Summary::overshoot_m},
    {"overshoot_percent", &Summary::overshoot_percent},
    {"settling_band_m", &Summary::settling_band_m},
    {"settling_time_s", &Summary::settling_time_s},
    {"settle_after_move_s", &Summary::settle_after_move_s},
    {"position_error_max_abs_during_move_m", &Summary::position_error_max_abs_during_move_m},
    {"position_error_rms_during_move_m", &Summary::position_error_rms_during_move_m},
    {"position_error_max_abs_after_move_m", &Summary::position_error_max_abs_after_move_m}};
double saturated(long double v) { return v > kLargest ? kLargest : v < -kLargest ? -kLargest : static_cast<double>(v); }
}  // namespace

void SummaryBuilder::add(const Record& q) {
  const double e = saturated(static_cast<long double>(q.xd) - q.x);
  const double ev = saturated(static_cast<long double>(q.vd) - q.v);
  Summary& m = m_;
  if (n_ == 0) {
    m.control_min = m.control_max = q.u;
    m.max_position_m = m.min_position_m = q.x;
  }
  // The error metrics are over the steps that have a true state (a record from hardware has
  // none: truth.valid = 0 gives NaN): a metric over no such step has no value (null), never 0.
  const bool settled = q.t >= settled_after_;
  // Against the measured position: every run has one (a record without it, NaN, is skipped).
  if (const double em = saturated(static_cast<long double>(q.xd) - q.x_measured); std::isfinite(em)) {
    abs_em_.add(std::abs(em));
    m.measured_position_error_max_abs_m = std::max(m.measured_position_error_max_abs_m, std::abs(em));
    sem_ += static_cast<long double>(em) * em;
    ++n_em_;
  }
  if (std::isfinite(e)) {
    abs_e_.add(std::abs(e));
    m.position_error_max_abs_m = std::max(m.position_error_max_abs_m, std::abs(e));
    se_ += static_cast<long double>(e) * e;
    ++n_e_;
    if (settled) {
      m.position_error_max_abs_settled_m = std::max(m.position_error_max_abs_settled_m, std::abs(e));
      se_settled_ += static_cast<long double>(e) * e;
      ++n_e_settled_;
    }
  }
  if (std::isfinite(ev)) {
    m.velocity_error_max_abs_mps = std::max(m.velocity_error_max_abs_mps, std::abs(ev));
    if (n_ > 0) {
      m.velocity_error_max_abs_after_first_mps = std::max(m.velocity_error_max_abs_after_first_mps, std::abs(ev));
      ++n_ev_after_first_;
    }
    sev_ += static_cast<long double>(ev) * ev;
    ++n_ev_;
    if (settled) {
      m.velocity_error_max_abs_settled_mps = std::max(m.velocity_error_max_abs_settled_mps, std::abs(ev));
      ++n_ev_settled_;
    }
  }
  if (settled) ++n_settled_;
  if (is_move_) add_move(q);
  if (n_ > 0) {  // chatter: opposite signs of two successive command steps, both >= delta
    const double du = q.u - last_.u;
    if (std::abs(du) >= chatter_delta_ && chatter_delta_ > 0.0) {
      if (du * du_prev_ < 0.0) ++reversals_;
      du_prev_ = du;
    } else {
      du_prev_ = 0.0;
    }
  }
  m.control_min = std::min(m.control_min, q.u);
  m.control_max = std::max(m.control_max, q.u);
  if (n_ > 0) total_variation_ += std::abs(static_cast<long double>(q.u) - last_.u);
  if (q.u != q.u_unsaturated) ++m.control_saturated_steps;
  add_signal(q.u);
  m.max_position_m = std::max(m.max_position_m, q.x);
  m.min_position_m = std::min(m.min_position_m, q.x);
  last_ = q;
  ++n_;
}

void SummaryBuilder::add_signal(double u) {
  // long double (as the sums): a finite but absurd command (1e308 V) keeps a finite force
  const long double force = static_cast<long double>(thrust_gain_) * u;
  if (n_ == 0) {
    extreme_ = u;
    hx1_ = hx2_ = force;  // at rest on the first force: a constant passes as 0
  } else {
    const long double du = static_cast<long double>(u) - last_.u;
    sdu_ += du * du;
    // turning points with hysteresis h: extreme_ is the running max (rising) or min (falling),
    // or the first u until u has moved h away from it
    const double h = std::max(direction_band_, std::numeric_limits<double>::min());
    if (direction_ == 1) {
      if (u > extreme_) {
        extreme_ = u;
      } else if (extreme_ - u >= h) {
        ++direction_changes_;
        direction_ = -1;
        extreme_ = u;
      }
    } else if (direction_ == -1) {
      if (u < extreme_) {
        extreme_ = u;
      } else if (u - extreme_ >= h) {
        ++direction_changes_;
        direction_ = 1;
        extreme_ = u;
      }
    } else if (std::abs(u - extreme_) >= h) {
      direction_ = u > extreme_ ? 1 : -1;
      extreme_ = u;
    }
  }
  if (hf_defined_) {
    const long double y = hb0_ * (force - 2.0L * hx1_ + hx2_) - ha1_ * hy1_ - ha2_ * hy2_;
    hx2_ = hx1_;
    hx1_ = force;
    hy2_ = hy1_;
    hy1_ = y;
    shf_ += y * y;
  }
}

void SummaryBuilder::add_move(const Record& q) {
  const double y = std::isfinite(q.x) ? q.x : q.x_measured;
  if (!std::isfinite(y)) return;
  if (std::isnan(move_start_)) {
    if (q.xd == x0_) return;  // not started
    move_start_ = q.t;
  }
  const double sign = distance_ >= 0.0 ? 1.0 : -1.0;
  if (distance_ != 0.0) {
    const double progress = (y - x0_) / distance_;  // 0 at the start, 1 at the target
    if (std::isnan(t10_) && progress >= 0.1) t10_ = q.t;
    if (std::isnan(t90_) && progress >= 0.9) t90_ = q.t;
    overshoot_ = std::max(overshoot_, sign * (y - target_));
  }
  // t_in: the first in-band step after the last out-of-band one (the move start if none was out)
  if (std::abs(y - target_) > band_) {
    last_out_ = true;
  } else if (last_out_ || std::isnan(t_in_)) {
    t_in_ = last_out_ ? q.t : move_start_;
    last_out_ = false;
  }
  const double e = std::abs(q.xd - y);
  if (q.t <= move_end_) {
    max_during_ = std::max(max_during_, e);
    se_during_ += static_cast<long double>(e) * e;
    ++n_during_;
  } else {
    max_after_ = std::max(max_after_, e);
    ++n_after_;
  }
}

void SummaryBuilder::finish_move(Summary& m) const {
  if (!is_move_) return;
  m.move_end_s = move_end_;
  m.move_distance_m = distance_;
  if (std::isnan(move_start_)) return;  // the reference has not moved yet
  m.move_start_s = move_start_;
  if (distance_ != 0.0) {
    if (!std::isnan(t10_) && !std::isnan(t90_)) m.rise_time_s = t90_ - t10_;
  }
  // An overshoot exists only for a move that ended within the run (null otherwise, never 0).
  if (distance_ != 0.0 && last_.t >= move_end_) {
    m.overshoot_m = overshoot_;
    m.overshoot_percent = 100.0 * overshoot_ / std::abs(distance_);
  }
  if (band_ > 0.0) {
    m.settling_band_m = band_;
    const bool ended = last_.t >= move_end_;  // the reference has stopped within the run
    if (ended && !last_out_ && !std::isnan(t_in_)) {
      m.settling_time_s = t_in_ - move_start_;
      m.settle_after_move_s = std::max(0.0, t_in_ - move_end_);
    }
  }
  if (n_during_ > 0) {
    m.position_error_max_abs_during_move_m = max_during_;
    m.position_error_rms_during_move_m =
        static_cast<double>(std::sqrt(se_during_ / static_cast<long double>(n_during_)));
  }
  if (n_after_ > 0) m.position_error_max_abs_after_move_m = max_after_;
}

void SummaryBuilder::finish_signal(Summary& m) const {
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  const auto n = static_cast<long double>(n_);
  m.control_step_rms_V = n_ > 1 ? saturated(std::sqrt(sdu_ / (n - 1.0L))) : kNone;
  m.control_direction_changes_per_s = m.sim_time_s > 0.0 ? static_cast<double>(direction_changes_) / m.sim_time_s : 0.0;
  m.control_saturated_fraction = static_cast<double>(m.control_saturated_steps) / static_cast<double>(n_);
  m.force_hf_rms_N = hf_defined_ ? saturated(std::sqrt(shf_ / n)) : kNone;
  const SignalLimits& l = kSignalLimits;
  // Every limit that has a value must hold (a run of one step has no step-to-step change; a
  // rate without content above f_c has no HF figure: those limits are not checked).
  m.control_signal_within_limits = !(m.control_step_rms_V > l.step_rms_deltas * chatter_delta_) &&
                                   m.control_direction_changes_per_s <= l.direction_changes_per_s &&
                                   m.control_saturated_fraction <= l.saturated_fraction &&
                                   !(m.force_hf_rms_N > m.force_hf_limit_N);
}

Summary SummaryBuilder::summary(double wall_time_s,
                                const std::optional<plant::CvodeIntegrator::Stats>& integrator) const {
  Summary m = m_;
  m.steps = n_;
  m.sim_time_s = static_cast<double>(n_) * control_period_;
  m.wall_time_s = wall_time_s;
  m.settled_steps = n_settled_;
  m.integrator_known = integrator.has_value();
  if (integrator) {
    m.integrator_steps = integrator->steps;
    m.integrator_rhs_evals = integrator->rhs_evals;
    m.integrator_jac_evals = integrator->jac_evals;
    m.integrator_error_test_fails = integrator->error_test_fails;
  }
  if (n_ == 0) return m;
  finish_move(m);
  m.control_reversals_per_s = m.sim_time_s > 0.0 ? static_cast<double>(reversals_) / m.sim_time_s : 0.0;
  m.control_chattering = m.control_reversals_per_s >= 0.05 / control_period_;
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();  // written as null
  m.position_error_rms_m = n_e_ > 0 ? static_cast<double>(std::sqrt(se_ / static_cast<long double>(n_e_))) : kNone;
  m.velocity_error_rms_mps = n_ev_ > 0 ? static_cast<double>(std::sqrt(sev_ / static_cast<long double>(n_ev_))) : kNone;
  m.control_total_variation = saturated(total_variation_);
  finish_signal(m);
  if (n_settled_ > 0)
    m.position_error_rms_settled_m =
        n_e_settled_ > 0 ? static_cast<double>(std::sqrt(se_settled_ / static_cast<long double>(n_e_settled_))) : kNone;
  // rank floor(0.95 n) of the n finite values |e| (and |e_m|)
  const auto p95 = [](const stats::StreamingQuantile& q, double& out) {
    if (q.count() == 0) return;
    out = q.value_at_rank(
        std::min<std::uint64_t>(q.count() - 1, static_cast<std::uint64_t>(0.95 * static_cast<double>(q.count()))));
  };
  p95(abs_e_, m.position_error_p95_abs_m);
  p95(abs_em_, m.measured_position_error_p95_abs_m);
  m.measured_position_error_rms_m =
      n_em_ > 0 ? static_cast<double>(std::sqrt(sem_ / static_cast<long double>(n_em_))) : kNone;
  if (n_em_ == 0) m.measured_position_error_max_abs_m = m.measured_position_error_p95_abs_m = kNone;
  if (n_e_ == 0) m.position_error_max_abs_m = m.position_error_p95_abs_m = kNone;
  if (n_e_settled_ == 0) m.position_error_max_abs_settled_m = kNone;
  if (n_ev_ == 0) m.velocity_error_max_abs_mps = kNone;
  if (n_ev_after_first_ == 0) m.velocity_error_max_abs_after_first_mps = kNone;
  if (n_ev_settled_ == 0) m.velocity_error_max_abs_settled_mps = kNone;
  m.final_position_m = last_.x;
  m.final_velocity_mps = last_.v;
  m.final_bristle_m = last_.z;
  m.final_friction_N = last_.f_friction;
  return m;
}

Summary summarize(const RunResult& r, const Scenario& s) {
  SummaryBuilder b(s);
  for (const Record& q : r.records) b.add(q);
  return b.summary(r.wall_time_s, r.integrator);
}

namespace {
nlohmann::ordered_json summary_object(const Summary& m, const Scenario& s);

template <class Json>
std::string headline_of(const Json& j) {
  const auto num = [&](const char* key) -> std::string {
    if (!j.contains(key) || !j[key].is_number()) return "n/a";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", j[key].template get<double>());
    return buf;
  };
  // The true-state error where the plant has one, else the measured one (a hardware plant).
  const bool truth = j.contains("position_error_max_abs_m") && j["position_error_max_abs_m"].is_number();
  std::string line =
      truth ? "max |e| = " + num("position_error_max_abs_m") + " m, rms e = " + num("position_error_rms_m") + " m"
            : "max |e_m| = " + num("measured_position_error_max_abs_m") +
                  " m, rms e_m = " + num("measured_position_error_rms_m") + " m (measured: x_d - x_measured)";
  line += ", u in [" + num("control_min") + ", " + num("control_max") + "] V";
  if (j.contains("settling_time_s") && j["settling_time_s"].is_number())
    line += ", settles to " + num("settling_band_m") + " m in " + num("settling_time_s") + " s";
  else if (j.contains("move_start_s") && j["move_start_s"].is_number() && j.contains("settling_band_m") &&
           j["settling_band_m"].is_number() && j.contains("move_end_s") && j["move_end_s"].is_number() &&
           j["move_end_s"].template get<double>() <= j.value("sim_time_s", 0.0))  // a move that ended within the run
    line += ", NOT SETTLED to " + num("settling_band_m") + " m";
  if (j.contains("move_finished") && j["move_finished"] == false) line += ", MOVE CUT OFF at the end of the run";
  if (j.value("control_chattering", false))
    line += ", CONTROL CHATTERS (" + num("control_reversals_per_s") +
            " reversals/s of steps >= " + num("control_chatter_threshold_V") + " V)";
  if (j.contains("control_signal_within_limits") && j["control_signal_within_limits"] == false)
    line += ", CONTROL SIGNAL OUTSIDE LIMITS (step rms " + num("control_step_rms_V") + " V, " +
            num("control_direction_changes_per_s") + " direction changes/s, " + num("force_hf_rms_N") +
            " N above 1 kHz, saturated " + num("control_saturated_fraction") + ")";
  if (j.contains("controller_model") &&
      (j["controller_model"] == "plant" || j["controller_model"] == "plant_without_effects"))
    line += ", model = " + j["controller_model"].template get<std::string>();
  return line;
}
}  // namespace

std::string summary_headline(const std::string& text) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return "no summary";
  return headline_of(j);
}

std::string summary_headline(const Summary& m, const Scenario& s) { return headline_of(summary_object(m, s)); }

namespace {
// long-function: a flat list, one line per field of summary.json in its documented order (docs/scenario.md).
// The one assembly of the summary's fields (summary_json writes it, summary_metrics reads its
// numbers without a text round trip).
nlohmann::ordered_json summary_object(const Summary& m, const Scenario& s) {
  nlohmann::ordered_json j;
  // Metrics over an empty window are null (summary.hpp), never 0.
  const auto val = [&](double v) { return m.steps > 0 ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); };
  const auto settled = [&](double v) {
    return m.settled_steps > 0 ? nlohmann::ordered_json(v) : nlohmann::ordered_json();
  };
  j["scenario"] = s.name;
  j["scenario_path"] = s.path;
  j["control_period_s"] = s.control_period;
  j["steps"] = m.steps;
  j["sim_time_s"] = m.sim_time_s;
  j["wall_time_s"] = m.wall_time_s;
  j["realtime_factor"] = m.wall_time_s > 0.0 ? m.sim_time_s / m.wall_time_s : 0.0;
  j["position_error_max_abs_m"] = val(m.position_error_max_abs_m);
  j["position_error_rms_m"] = val(m.position_error_rms_m);
  j["position_error_p95_abs_m"] = val(m.position_error_p95_abs_m);
  j["measured_position_error_max_abs_m"] = val(m.measured_position_error_max_abs_m);
  j["measured_position_error_rms_m"] = val(m.measured_position_error_rms_m);
  j["measured_position_error_p95_abs_m"] = val(m.measured_position_error_p95_abs_m);
  // Which error the headline figure is (launcher line, plots): the true state's where it exists.
  j["error_source"] = m.steps == 0
                          ? nlohmann::ordered_json()
                          : nlohmann::ordered_json(std::isnan(m.position_error_max_abs_m) ? "measured" : "true_state");
  j["velocity_error_max_abs_mps"] = val(m.velocity_error_max_abs_mps);
  j["velocity_error_max_abs_after_first_mps"] =
      m.steps > 1 ? nlohmann::ordered_json(m.velocity_error_max_abs_after_first_mps) : nlohmann::ordered_json();
  j["velocity_error_rms_mps"] = val(m.velocity_error_rms_mps);
  j["settled_after_s"] = m.settled_after_s;
  j["position_error_max_abs_settled_m"] = settled(m.position_error_max_abs_settled_m);
  j["position_error_rms_settled_m"] = settled(m.position_error_rms_settled_m);
  j["velocity_error_max_abs_settled_mps"] = settled(m.velocity_error_max_abs_settled_mps);
  j["control_min"] = val(m.control_min);
  j["control_max"] = val(m.control_max);
  j["control_total_variation"] = val(m.control_total_variation);
  j["control_saturated_steps"] = m.control_saturated_steps;
  j["final_position_m"] = val(m.final_position_m);
  j["final_velocity_mps"] = val(m.final_velocity_mps);
  j["final_bristle_m"] = val(m.final_bristle_m);
  j["final_friction_N"] = val(m.final_friction_N);
  j["max_position_m"] = val(m.max_position_m);
  j["min_position_m"] = val(m.min_position_m);
  // The plant's CVODE counts where it ran in this process; null where it ran elsewhere (never 0).
  const auto counted = [&](long v) {
    return m.integrator_known ? nlohmann::ordered_json(v) : nlohmann::ordered_json();
  };
  j["integrator_steps"] = counted(m.integrator_steps);
  j["integrator_rhs_evals"] = counted(m.integrator_rhs_evals);
  j["integrator_jac_evals"] = counted(m.integrator_jac_evals);
  j["integrator_error_test_fails"] = counted(m.integrator_error_test_fails);
  // Move and step metrics (summary.hpp): null where they do not apply.
  const auto opt = [&](double v) {
    return m.steps > 0 && std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json();
  };
  for (const auto& [key, field] : kMoveFields) j[key] = opt(m.*field);
  // Chatter (summary.hpp): reversals of the command's steps larger than the threshold.
  j["control_chatter_threshold_V"] = m.control_chatter_threshold_V;
  j["control_reversals_per_s"] = val(m.control_reversals_per_s);
  j["control_chattering"] = m.steps > 0 ? nlohmann::ordered_json(m.control_chattering) : nlohmann::ordered_json();
  // Control-signal quality (summary.hpp, docs/scenario.md "Control-signal quality").
  j["control_step_rms_V"] = opt(m.control_step_rms_V);
  j["control_direction_band_V"] = m.control_direction_band_V;
  j["control_direction_changes_per_s"] = val(m.control_direction_changes_per_s);
  j["control_saturated_fraction"] = val(m.control_saturated_fraction);
  j["force_hf_corner_Hz"] = m.force_hf_corner_Hz;
  j["force_hf_rms_N"] = opt(m.force_hf_rms_N);
  j["force_hf_limit_N"] = m.force_hf_limit_N;
  j["control_signal_within_limits"] =
      m.steps > 0 ? nlohmann::ordered_json(m.control_signal_within_limits) : nlohmann::ordered_json();
  // Whose parameters the controller's model holds: "plant" means every result is a
  // perfect-model result (docs/scenario.md).
  const std::string model = controller_model_source(s);
  j["controller_model"] = model.empty() ? nlohmann::ordered_json() : nlohmann::ordered_json(model);
  // The gains a cascade runs with (tuning: rule chooses them: docs/controllers.md).
  if (s.controller.type == ControllerType::kCascade)
    j["cascade_gains"] = {
        {"kp", s.controller.cascade.kp}, {"kv", s.controller.cascade.kv}, {"ki", s.controller.cascade.ki}};
  // Issue 23: a move the run cut off, and the loader's plausibility warnings (scenario.hpp).
  const std::optional<bool> finished = move_finished(s);
  j["move_finished"] = finished ? nlohmann::ordered_json(*finished) : nlohmann::ordered_json();  // null: not a move
  j["warnings"] = s.warnings;
  return j;
}
}  // namespace

std::string summary_json(const Summary& m, const Scenario& s, const std::string& extra) {
  nlohmann::ordered_json j = summary_object(m, s);
  if (!extra.empty()) {
    const nlohmann::ordered_json e = nlohmann::ordered_json::parse(extra);
    for (auto it = e.begin(); it != e.end(); ++it) j[it.key()] = it.value();
  }
  // A path that is not UTF-8 (the name is checked at load time) is written with U+FFFD, never an
  // exception after the run.
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

std::optional<bool> move_finished(const Scenario& s) {
  if (std::isnan(s.move_end_s)) return std::nullopt;
  return s.move_end_s <= s.duration;
}

bool is_wall_clock_metric(const std::string& key) { return key == "wall_time_s" || key == "realtime_factor"; }

namespace {
// The summary of a run with steps whose every windowed and move metric has a value.
Summary a_full_run() {
  Summary m;
  m.steps = 2;
  m.settled_steps = 2;  // every windowed metric a number, not null (the after-first ones need 2 steps)
  m.integrator_known = true;
  for (const auto& [key, field] : kMoveFields) m.*field = 0.0;  // numbers for a move
  m.control_step_rms_V = m.force_hf_rms_N = 0.0;                // and for a rate above 2 kHz
  return m;
}
// move_finished is a verdict of summary.json, but a study records it in a column of its own
// (with the case's warnings: study/runner.hpp), not among the metrics.
bool is_metric_verdict(const std::string& key) { return key != "move_finished"; }
}  // namespace

std::vector<std::string> summary_metric_names() {
  const nlohmann::ordered_json j = summary_object(a_full_run(), Scenario{});
  std::vector<std::string> names;
  for (auto it = j.begin(); it != j.end(); ++it)
    if (it.value().is_number() && !is_wall_clock_metric(it.key())) names.push_back(it.key());
  return names;
}

std::vector<std::string> summary_flag_names() {
  Scenario s;
  s.move_end_s = 0.0;  // a move: move_finished true/false, not null
  const nlohmann::ordered_json j = summary_object(a_full_run(), s);
  std::vector<std::string> names;
  for (auto it = j.begin(); it != j.end(); ++it)
    if (it.value().is_boolean() && is_metric_verdict(it.key())) names.push_back(it.key());
  return names;
}

std::vector<std::pair<std::string, double>> summary_metrics(const Summary& m, const Scenario& s) {
  const nlohmann::ordered_json j = summary_object(m, s);
  std::vector<std::pair<std::string, double>> out;
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it.value().is_boolean() && is_metric_verdict(it.key()))  // a verdict: 1 true, 0 false
      out.emplace_back(it.key(), it.value().get<bool>() ? 1.0 : 0.0);
    else if (it.value().is_number() && !is_wall_clock_metric(it.key()))
      out.emplace_back(it.key(), it.value().get<double>());
  }
  return out;
}

}  // namespace feeddrive::sim
