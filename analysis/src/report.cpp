// The outputs of the frequency response: the printed table, frequency_response.csv and .json,
// and the Bode plots (gnuplot, through output::StagedFolder as every tool's plots).
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "feeddrive/analysis/frequency_response.hpp"
#include "feeddrive/output/csv.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/output/gnuplot.hpp"
#include "feeddrive/sim/summary.hpp"

namespace feeddrive::analysis {
namespace {

std::string g(double v, const char* fmt = "%.4g") {
  if (std::isnan(v)) return "n/a";
  char b[40];
  std::snprintf(b, sizeof b, fmt, v);
  return b;
}
double db(std::complex<double> h) { return 20.0 * std::log10(std::abs(h)); }

std::string controller_text(const sim::Scenario& s) {
  static const char* const kNames[] = {"sliding_mode", "cascade", "open_loop", "plugin"};
  std::string t = kNames[static_cast<int>(s.controller.type)];
  const std::string model = sim::controller_model_source(s);
  if (!model.empty()) t += ", model = " + model;
  return t;
}

// Where a figure could not be found in the measured range, say why (never a silent blank).
std::string bandwidth_text(const FrequencyResponse& r) {
  if (!(r.options.reference_amplitude > 0.0)) return "not measured (--fr-amplitude 0)";
  if (!std::isnan(r.bandwidth_hz))
    return g(r.bandwidth_hz) + " Hz (interpolated in log f between the measured points " +
           g(r.bandwidth_between_hz[0]) + " and " + g(r.bandwidth_between_hz[1]) + " Hz)";
  if (r.bandwidth_outside < 0) return "below the lowest frequency measured";
  if (r.bandwidth_outside > 0) return "above the highest frequency measured (|T| >= -3 dB throughout)";
  return "none (every point doubtful)";
}

std::string peak_text(const FrequencyResponse& r) {
  if (!(r.options.reference_amplitude > 0.0)) return "peak |T|: not measured (--fr-amplitude 0)";
  if (std::isnan(r.peak_db)) return "peak |T|: none (every point doubtful)";
  if (r.peak_inside) return "peak |T| " + g(r.peak_db, "%.2f") + " dB at " + g(r.peak_hz) + " Hz";
  const bool low = !r.points.empty() && r.peak_hz <= r.points.front().frequency_hz * (1 + 1e-12);
  return std::string("no peak inside the measured range (|T| largest at the ") + (low ? "lowest" : "highest") +
         " frequency: " + g(r.peak_db, "%.2f") + " dB at " + g(r.peak_hz) + " Hz)";
}

std::string margins_text(const FrequencyResponse& r) {
  std::ostringstream t;
  const std::string top = r.points.empty() ? "n/a" : g(r.points.back().frequency_hz);
  t << "peak sensitivity Ms " << g(r.sensitivity_peak, "%.3f") << " (" << g(20 * std::log10(r.sensitivity_peak), "%.2f")
    << " dB) at " << g(r.sensitivity_peak_hz) << " Hz; ";
  if (std::isnan(r.phase_margin_deg))
    t << "phase margin: none found (|L| does not cross 0 dB downward up to " << top << " Hz)";
  else t << "phase margin " << g(r.phase_margin_deg, "%.1f") << " deg at " << g(r.crossover_hz) << " Hz";
  if (!std::isnan(r.crossover_hz) && std::isnan(r.gain_margin_db))
    t << "; gain margin: none found (arg L does not cross -180 deg above the crossover up to " << top << " Hz)";
  else if (!std::isnan(r.gain_margin_db))
    t << "; gain margin " << g(r.gain_margin_db, "%.1f") << " dB at " << g(r.phase_crossover_hz) << " Hz";
  if (!std::isnan(r.lower_gain_margin_db))
    t << "; lower gain margin " << g(r.lower_gain_margin_db, "%.1f") << " dB at " << g(r.lower_phase_crossover_hz)
      << " Hz (arg L crosses -180 deg below the crossover: conditionally stable, a loop gain lowered by "
      << g(-r.lower_gain_margin_db, "%.1f") << " dB is unstable)";
  return t.str();
}

// The frequencies whose response is mostly not at the excitation's frequency, or drifts.
std::string doubtful_points(const FrequencyResponse& r) {
  std::string out;
  for (const FrequencyPoint& p : r.points)
    if (p.doubtful()) out += (out.empty() ? "" : ", ") + g(p.frequency_hz);
  return out;
}

// The phases along f, unwrapped (no jump of more than 180 deg between neighbours; the loop's from
// (-360, 0], as the margins take it): the table, the CSV and the plots show the same numbers.
struct Phases {
  std::vector<double> t, gd, l, s;
};
Phases phases(const FrequencyResponse& r) {
  std::vector<std::complex<double>> t, gd, l, si;
  for (const FrequencyPoint& p : r.points)
    t.push_back(p.closed_loop), gd.push_back(p.compliance), l.push_back(p.loop), si.push_back(p.sensitivity);
  return {unwrapped_phase_deg(t), unwrapped_phase_deg(gd), unwrapped_phase_deg(l, true), unwrapped_phase_deg(si)};
}

}  // namespace

std::string frequency_response_table(const sim::Scenario& s, const FrequencyResponse& r) {
  const FrequencyResponseOptions& o = r.options;
  std::ostringstream t;
  t << "frequency response of " << s.name << " (" << controller_text(s) << "), T = " << g(s.control_period)
    << " s, stepped sines\n";
  t << "excitation: reference amplitude min(" << g(o.reference_amplitude) << " m, " << g(r.acceleration_limit)
    << " m/s^2 / w^2); force " << g(o.force_amplitude) << " N at the amplifier input; feed velocity "
    << g(o.feed_velocity) << " m/s. Friction makes the result amplitude-dependent.\n";
  t << "   f [Hz]  A_ref [m]   |T| [dB]  arg T [deg]  k_dyn [N/um]  arg G_d [deg]  |L| [dB]  arg L [deg]  |S| [dB]  "
       "drift  nonfund  sat\n";
  const Phases ph = phases(r);
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    const FrequencyPoint& p = r.points[i];
    char line[256];
    std::snprintf(
        line, sizeof line, "%9.4g  %9.3g  %9s  %11s  %12s  %13s  %8s  %11s  %8s  %5s  %7s  %3ld%s\n", p.frequency_hz,
        p.reference_amplitude_m, p.has_reference ? g(db(p.closed_loop), "%.3f").c_str() : "-",
        p.has_reference ? g(ph.t[i], "%.2f").c_str() : "-", p.has_disturbance ? g(p.stiffness_N_per_um()).c_str() : "-",
        p.has_disturbance ? g(ph.gd[i], "%.1f").c_str() : "-", p.has_disturbance ? g(db(p.loop), "%.2f").c_str() : "-",
        p.has_disturbance ? g(ph.l[i], "%.1f").c_str() : "-",
        p.has_disturbance ? g(db(p.sensitivity), "%.2f").c_str() : "-",
        g(std::max(p.closed_loop_drift, p.disturbance_drift), "%.1e").c_str(),
        g(std::max(p.closed_loop_nonfundamental, p.disturbance_nonfundamental), "%.3f").c_str(), p.saturated_steps,
        p.doubtful() ? "  doubtful" : "");
    t << line;
  }
  t << "phases unwrapped along f (arg L from (-360, 0])\n";
  const std::string doubtful = doubtful_points(r);
  if (!doubtful.empty())
    t << "WARNING: at " << doubtful
      << " Hz more than half of the power of the position's response is at other frequencies (nonfund > 0.71) or the "
         "two "
      << "blocks differ by more than 10 %: the ratio there is not a frequency response (chatter, stick-slip, a "
         "response that "
      << "wanders), and those points are left out of every summary figure below (bandwidth, peak, Ms, margins, least "
         "stiffness). "
      << "What may help: an amplitude well above the chatter's, a longer --fr-settle (a transient), a smooth switching "
         "law.\n";
  t << "closed-loop bandwidth (-3 dB): " << bandwidth_text(r) << "; " << peak_text(r) << "\n";
  if (!(o.force_amplitude > 0.0)) {
    t << "peak sensitivity, phase and gain margins, dynamic stiffness: not measured (--fr-force 0)\n";
  } else {
    t << margins_text(r) << "\n";
    t << "least dynamic stiffness " << g(r.min_stiffness_N_per_um) << " N/um at " << g(r.min_stiffness_hz)
      << " Hz (force amplitude " << g(o.force_amplitude) << " N)\n";
  }
  return t.str();
}

namespace {

// frequency_response.csv: one row per frequency, NaN where a run (reference or disturbance) was
// not made.
void write_frequency_csv(output::StagedFolder& folder, const FrequencyResponse& r) {
  output::CsvWriter csv(folder.path("frequency_response.csv"),
                        {"frequency_Hz", "reference_amplitude_m", "T_dB", "T_deg", "compliance_m_per_N",
                         "compliance_deg", "stiffness_N_per_um", "L_dB", "L_deg", "S_dB", "S_deg", "T_drift",
                         "T_nonfundamental", "disturbance_drift", "disturbance_nonfundamental", "saturated_steps"});
  const double nan = std::nan("");
  const Phases ph = phases(r);
  const auto &t_deg = ph.t, &gd_deg = ph.gd, &l_deg = ph.l, &s_deg = ph.s;
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    const FrequencyPoint& p = r.points[i];
    const bool a = p.has_reference, d = p.has_disturbance;
    csv.row({p.frequency_hz, p.reference_amplitude_m, a ? db(p.closed_loop) : nan, a ? t_deg[i] : nan,
             d ? std::abs(p.compliance) : nan, d ? gd_deg[i] : nan, d ? p.stiffness_N_per_um() : nan,
             d ? db(p.loop) : nan, d ? l_deg[i] : nan, d ? db(p.sensitivity) : nan, d ? s_deg[i] : nan,
             a ? p.closed_loop_drift : nan, a ? p.closed_loop_nonfundamental : nan, d ? p.disturbance_drift : nan,
             d ? p.disturbance_nonfundamental : nan, static_cast<double>(p.saturated_steps)});
  }
  csv.close();
}

// frequency_response.json: the method, the excitation and the summary figures (null where not
// measured or not finite).
nlohmann::ordered_json frequency_json(const sim::Scenario& s, const FrequencyResponse& r) {
  const auto num = [](double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); };
  const FrequencyResponseOptions& o = r.options;
  nlohmann::ordered_json j;
  j["scenario"] = s.name;
  j["scenario_path"] = s.path;
  j["control_period_s"] = s.control_period;
  j["controller"] = controller_text(s);
  j["method"] =
      "stepped sines: per frequency a reference run and a disturbance run from the initial state; the first "
      "max(settle_cycles/f, settle_time) dropped, then two blocks of whole cycles (DFT at f)";
  j["excitation"] = {{"reference_amplitude_m", o.reference_amplitude},
                     {"acceleration_limit_mps2", r.acceleration_limit},
                     {"force_amplitude_N", o.force_amplitude},
                     {"force_injection", "amplifier input: u + F_d/(Ka*Kf), held over the period"},
                     {"feed_velocity_mps", o.feed_velocity},
                     {"settle_cycles", o.settle_cycles},
                     {"settle_time_s", o.settle_time},
                     {"block_cycles", o.block_cycles},
                     {"block_time_s", o.block_time}};
  j["bandwidth_hz"] = num(r.bandwidth_hz);
  j["bandwidth"] = bandwidth_text(r);
  j["bandwidth_between_hz"] = std::isnan(r.bandwidth_hz)
                                  ? nlohmann::ordered_json()
                                  : nlohmann::ordered_json({r.bandwidth_between_hz[0], r.bandwidth_between_hz[1]});
  // a resonance peak only inside the measured range (at its edge |T| is largest only where the range stops)
  j["closed_loop_peak_db"] = r.peak_inside ? num(r.peak_db) : nlohmann::ordered_json();
  j["closed_loop_peak_hz"] = r.peak_inside ? num(r.peak_hz) : nlohmann::ordered_json();
  j["closed_loop_peak"] = peak_text(r);
  j["sensitivity_peak"] = num(r.sensitivity_peak);
  j["sensitivity_peak_hz"] = num(r.sensitivity_peak_hz);
  j["phase_margin_deg"] = num(r.phase_margin_deg);
  j["crossover_hz"] = num(r.crossover_hz);
  j["gain_margin_db"] = num(r.gain_margin_db);
  j["phase_crossover_hz"] = num(r.phase_crossover_hz);
  j["lower_gain_margin_db"] = num(r.lower_gain_margin_db);
  j["lower_phase_crossover_hz"] = num(r.lower_phase_crossover_hz);
  if (!(o.force_amplitude > 0.0)) j["margins"] = "not measured (--fr-force 0)";
  j["min_dynamic_stiffness_N_per_um"] = num(r.min_stiffness_N_per_um);
  j["min_dynamic_stiffness_hz"] = num(r.min_stiffness_hz);
  const std::string doubtful = doubtful_points(r);
  j["doubtful_frequencies_hz"] = doubtful.empty() ? nlohmann::ordered_json() : nlohmann::ordered_json(doubtful);
  j["doubtful_points"] = "left out of every summary figure (not a frequency response)";
  j["warnings"] = r.warnings;
  j["wall_time_s"] = r.wall_time_s;
  return j;
}

// The gnuplot script of the Bode plots from frequency_response.csv: T (reference run); the
// dynamic stiffness, L and S (disturbance run).
std::string frequency_plot_script(const sim::Scenario& s, const FrequencyResponse& r) {
  const FrequencyResponseOptions& o = r.options;
  const bool a = r.points.front().has_reference, d = r.points.front().has_disturbance;
  std::ostringstream gp;
  gp << "data = 'frequency_response.csv'\nset logscale x\nset xlabel 'f [Hz]'\nset datafile missing 'nan'\n";
  if (a) {
    gp << "set output 'bode_reference.png'\nset multiplot layout 2,1 title "
       << output::gnuplot_string(s.name + ": reference -> position T, amplitude min(" + g(o.reference_amplitude) +
                                 " m, " + g(r.acceleration_limit) + " m/s^2 / w^2)")
       << "\nset ylabel '|T| [dB]'\nplot data using 1:3 with linespoints title '|T|', -3.01 with lines dt 2 title "
          "'-3 dB'\n"
       << "set ylabel 'arg T [deg]'\nplot data using 1:4 with linespoints title 'arg T'\nunset multiplot\n";
  }
  if (d) {
    gp << "set output 'bode_compliance.png'\nset multiplot layout 2,1 title "
       << output::gnuplot_string(s.name + ": dynamic stiffness 1/|x/F_d|, force " + g(o.force_amplitude) + " N")
       << "\nset logscale y\nset ylabel 'dynamic stiffness [N/um]'\nplot data using 1:7 with linespoints title "
          "'k_dyn'\n"
       << "unset logscale y\nset ylabel 'arg x/F_d [deg]'\nplot data using 1:6 with linespoints title 'arg "
          "G_d'\nunset multiplot\n";
    gp << "set output 'bode_loop.png'\nset multiplot layout 2,1 title "
       << output::gnuplot_string(s.name + ": loop at the force set-point, force " + g(o.force_amplitude) + " N")
       << "\nset ylabel 'magnitude [dB]'\nplot data using 1:8 with linespoints title '|L|', '' using 1:10 with "
          "linespoints "
          "title '|S|', 0 with lines dt 2 notitle\n"
       << "set ylabel 'arg L [deg]'\nplot data using 1:9 with linespoints title 'arg L', -180 with lines dt 2 "
          "notitle\n"
          "unset multiplot\n";
  }
  return gp.str();
}

}  // namespace

FrequencyResponseWritten write_frequency_response(const std::string& out_dir, const sim::Scenario& s,
                                                  const FrequencyResponse& r, bool plots,
                                                  const interrupt::StopToken& stop) {
  output::StagedFolder folder(out_dir, "feeddrive-sim");
  write_frequency_csv(folder, r);
  const nlohmann::ordered_json j = frequency_json(s, r);
  folder.write_text("frequency_response.json", j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  std::string plot_error;
  if (plots && !r.points.empty()) {
    try {
      folder.plot(frequency_plot_script(s, r), stop);
    } catch (const std::runtime_error& e) {
      plot_error = e.what();
    }
  }
  std::vector<std::string> warnings = folder.commit();
  return {plot_error, std::move(warnings)};
}

}  // namespace feeddrive::analysis
