#include "feeddrive/sim/summary.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

namespace feeddrive::sim {

Summary summarize(const RunResult& r, const Scenario& s) {
  Summary m;
  const auto& rec = r.records;
  m.steps = static_cast<long>(rec.size());
  m.sim_time_s = static_cast<double>(rec.size()) * s.control_period;
  m.wall_time_s = r.wall_time_s;
  m.settled_after_s = s.analysis.settled_after;
  m.integrator_steps = r.integrator.steps;
  m.integrator_rhs_evals = r.integrator.rhs_evals;
  m.integrator_jac_evals = r.integrator.jac_evals;
  m.integrator_error_test_fails = r.integrator.error_test_fails;
  if (rec.empty()) return m;

  double se = 0.0, sev = 0.0, se_settled = 0.0;
  double e_settled = 0.0, ev_settled = 0.0, ev_after_first = 0.0;
  long n_settled = 0;
  std::vector<double> abs_e;
  abs_e.reserve(rec.size());
  m.control_min = m.control_max = rec.front().u;
  m.max_position_m = m.min_position_m = rec.front().x;
  for (std::size_t k = 0; k < rec.size(); ++k) {
    const Record& q = rec[k];
    const double e = q.xd - q.x;
    const double ev = q.vd - q.v;
    abs_e.push_back(std::abs(e));
    m.position_error_max_abs_m = std::max(m.position_error_max_abs_m, std::abs(e));
    m.velocity_error_max_abs_mps = std::max(m.velocity_error_max_abs_mps, std::abs(ev));
    if (k > 0) ev_after_first = std::max(ev_after_first, std::abs(ev));
    se += e * e;
    sev += ev * ev;
    if (q.t >= s.analysis.settled_after) {
      e_settled = std::max(e_settled, std::abs(e));
      ev_settled = std::max(ev_settled, std::abs(ev));
      se_settled += e * e;
      ++n_settled;
    }
    m.control_min = std::min(m.control_min, q.u);
    m.control_max = std::max(m.control_max, q.u);
    if (k > 0) m.control_total_variation += std::abs(q.u - rec[k - 1].u);
    if (q.u != q.u_unsaturated) ++m.control_saturated_steps;
    m.max_position_m = std::max(m.max_position_m, q.x);
    m.min_position_m = std::min(m.min_position_m, q.x);
  }
  const double n = static_cast<double>(rec.size());
  m.position_error_rms_m = std::sqrt(se / n);
  m.velocity_error_rms_mps = std::sqrt(sev / n);
  if (rec.size() > 1) m.velocity_error_max_abs_after_first_mps = ev_after_first;
  m.settled_steps = n_settled;
  if (n_settled > 0) {
    m.position_error_max_abs_settled_m = e_settled;
    m.position_error_rms_settled_m = std::sqrt(se_settled / static_cast<double>(n_settled));
    m.velocity_error_max_abs_settled_mps = ev_settled;
  }
  const std::size_t i95 = std::min(abs_e.size() - 1, static_cast<std::size_t>(0.95 * n));
  std::nth_element(abs_e.begin(), abs_e.begin() + static_cast<long>(i95), abs_e.end());
  m.position_error_p95_abs_m = abs_e[i95];
  const Record& last = rec.back();
  m.final_position_m = last.x;
  m.final_velocity_mps = last.v;
  m.final_bristle_m = last.z;
  m.final_friction_N = last.f_friction;
  return m;
}

std::string summary_json(const Summary& m, const Scenario& s, const std::string& extra) {
  nlohmann::ordered_json j;
  // Metrics over an empty window are null (summary.hpp), never 0.
  const auto opt = [](const std::optional<double>& v) { return v ? nlohmann::ordered_json(*v) : nlohmann::ordered_json(); };
  const auto val = [&](double v) { return m.steps > 0 ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); };
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
  j["velocity_error_max_abs_mps"] = val(m.velocity_error_max_abs_mps);
  j["velocity_error_max_abs_after_first_mps"] = opt(m.velocity_error_max_abs_after_first_mps);
  j["velocity_error_rms_mps"] = val(m.velocity_error_rms_mps);
  j["settled_after_s"] = m.settled_after_s;
  j["position_error_max_abs_settled_m"] = opt(m.position_error_max_abs_settled_m);
  j["position_error_rms_settled_m"] = opt(m.position_error_rms_settled_m);
  j["velocity_error_max_abs_settled_mps"] = opt(m.velocity_error_max_abs_settled_mps);
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
  j["integrator_steps"] = m.integrator_steps;
  j["integrator_rhs_evals"] = m.integrator_rhs_evals;
  j["integrator_jac_evals"] = m.integrator_jac_evals;
  j["integrator_error_test_fails"] = m.integrator_error_test_fails;
  if (!extra.empty()) {
    const nlohmann::ordered_json e = nlohmann::ordered_json::parse(extra);
    for (auto it = e.begin(); it != e.end(); ++it) j[it.key()] = it.value();
  }
  // A path that is not UTF-8 (the name is checked at load time) is written with U+FFFD, never an
  // exception after the run.
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace feeddrive::sim
