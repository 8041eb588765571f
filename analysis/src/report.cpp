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

constexpr double kDeg = 180.0 / 3.14159265358979323846;

std::string g(double v, const char* fmt = "%.4g") {
  if (std::isnan(v)) return "n/a";
  char b[40];
  std::snprintf(b, sizeof b, fmt, v);
  return b;
}
double db(std::complex<double> h) { return 20.0 * std::log10(std::abs(h)); }
double deg(std::complex<double> h) { return std::arg(h) * kDeg; }

std::string controller_text(const sim::Scenario& s) {
  static const char* const kNames[] = {"sliding_mode", "cascade", "open_loop", "plugin"};
  std::string t = kNames[static_cast<int>(s.controller.type)];
  const std::string model = sim::controller_model_source(s);
  if (!model.empty()) t += ", model = " + model;
  return t;
}

// Where a figure could not be found in the measured range, say why (never a silent blank).
std::string bandwidth_text(const FrequencyResponse& r) {
  if (!std::isnan(r.bandwidth_hz)) return g(r.bandwidth_hz) + " Hz";
  if (r.points.empty() || !r.points.front().has_reference) return "n/a (no reference run)";
  if (db(r.points.front().closed_loop) < -3.0103) return "below the lowest frequency measured";
  return "above the highest frequency measured (|T| >= -3 dB throughout)";
}

// The frequencies whose response is mostly not at the excitation's frequency, or drifts.
std::string doubtful_points(const FrequencyResponse& r) {
  std::string out;
  for (const FrequencyPoint& p : r.points)
    if (std::max(p.closed_loop_nonfundamental, p.disturbance_nonfundamental) > 0.5 * std::sqrt(2.0) ||
        std::max(p.closed_loop_drift, p.disturbance_drift) > 0.1)
      out += (out.empty() ? "" : ", ") + g(p.frequency_hz);
  return out;
}

}  // namespace

std::string frequency_response_table(const sim::Scenario& s, const FrequencyResponse& r) {
  const FrequencyResponseOptions& o = r.options;
  std::ostringstream t;
  t << "frequency response of " << s.name << " (" << controller_text(s) << "), T = " << g(s.control_period) << " s, stepped sines\n";
  t << "excitation: reference amplitude min(" << g(o.reference_amplitude) << " m, " << g(r.acceleration_limit)
    << " m/s^2 / w^2); force " << g(o.force_amplitude) << " N at the amplifier input; feed velocity " << g(o.feed_velocity)
    << " m/s. Friction makes the result amplitude-dependent.\n";
  t << "   f [Hz]  A_ref [m]   |T| [dB]  arg T [deg]  k_dyn [N/um]  arg G_d [deg]  |L| [dB]  arg L [deg]  |S| [dB]  drift  nonfund  sat\n";
  for (const FrequencyPoint& p : r.points) {
    char line[256];
    std::snprintf(line, sizeof line, "%9.4g  %9.3g  %9s  %11s  %12s  %13s  %8s  %11s  %8s  %5s  %7s  %3ld\n", p.frequency_hz,
                  p.reference_amplitude_m, p.has_reference ? g(db(p.closed_loop), "%.3f").c_str() : "-",
                  p.has_reference ? g(deg(p.closed_loop), "%.2f").c_str() : "-",
                  p.has_disturbance ? g(p.stiffness_N_per_um()).c_str() : "-", p.has_disturbance ? g(deg(p.compliance), "%.1f").c_str() : "-",
                  p.has_disturbance ? g(db(p.loop), "%.2f").c_str() : "-", p.has_disturbance ? g(deg(p.loop), "%.1f").c_str() : "-",
                  p.has_disturbance ? g(db(p.sensitivity), "%.2f").c_str() : "-",
                  g(std::max(p.closed_loop_drift, p.disturbance_drift), "%.1e").c_str(),
                  g(std::max(p.closed_loop_nonfundamental, p.disturbance_nonfundamental), "%.3f").c_str(), p.saturated_steps);
    t << line;
  }
  t << "closed-loop bandwidth (-3 dB): " << bandwidth_text(r) << "; peak |T| " << g(r.peak_db, "%.2f") << " dB at " << g(r.peak_hz)
    << " Hz\n";
  const std::string top = r.points.empty() ? "n/a" : g(r.points.back().frequency_hz);
  t << "peak sensitivity Ms " << g(r.sensitivity_peak, "%.3f") << " (" << g(20 * std::log10(r.sensitivity_peak), "%.2f") << " dB) at "
    << g(r.sensitivity_peak_hz) << " Hz; ";
  if (std::isnan(r.phase_margin_deg)) t << "phase margin: none found (|L| does not cross 0 dB downward up to " << top << " Hz)";
  else t << "phase margin " << g(r.phase_margin_deg, "%.1f") << " deg at " << g(r.crossover_hz) << " Hz";
  if (std::isnan(r.gain_margin_db)) t << "; gain margin: none found (arg L does not cross -180 deg above the crossover up to " << top << " Hz)\n";
  else t << "; gain margin " << g(r.gain_margin_db, "%.1f") << " dB at " << g(r.phase_crossover_hz) << " Hz\n";
  const std::string doubtful = doubtful_points(r);
  if (!doubtful.empty())
    t << "WARNING: at " << doubtful << " Hz more than half of the power of the position's response is at other frequencies (nonfund > 0.71) or the two "
      << "blocks differ by more than 10 %: the ratio there is not a frequency response (chatter, stick-slip, a response that "
      << "wanders), and the figures above that use those points are doubtful. What may help: an amplitude well above the "
      << "chatter's, a longer --fr-settle (a transient), a smooth switching law.\n";
  t << "least dynamic stiffness " << g(r.min_stiffness_N_per_um) << " N/um at " << g(r.min_stiffness_hz) << " Hz (force amplitude "
    << g(o.force_amplitude) << " N)\n";
  return t.str();
}

std::string write_frequency_response(const std::string& out_dir, const sim::Scenario& s, const FrequencyResponse& r, bool plots,
                                     const interrupt::StopToken& stop) {
  output::StagedFolder folder(out_dir, "feeddrive-sim");
  {
    output::CsvWriter csv(folder.path("frequency_response.csv"),
                          {"frequency_Hz", "reference_amplitude_m", "T_dB", "T_deg", "compliance_m_per_N", "compliance_deg",
                           "stiffness_N_per_um", "L_dB", "L_deg", "S_dB", "S_deg", "T_drift", "T_nonfundamental",
                           "disturbance_drift", "disturbance_nonfundamental", "saturated_steps"});
    const double nan = std::nan("");
    // phases unwrapped along the frequency axis (the loop's from (-360, 0], as the margins take it)
    std::vector<std::complex<double>> t, gd, l, si;
    for (const FrequencyPoint& p : r.points) {
      t.push_back(p.closed_loop), gd.push_back(p.compliance), l.push_back(p.loop), si.push_back(p.sensitivity);
    }
    const auto t_deg = unwrapped_phase_deg(t), gd_deg = unwrapped_phase_deg(gd), l_deg = unwrapped_phase_deg(l, true),
               s_deg = unwrapped_phase_deg(si);
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
  const auto num = [](double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); };
  const FrequencyResponseOptions& o = r.options;
  nlohmann::ordered_json j;
  j["scenario"] = s.name;
  j["scenario_path"] = s.path;
  j["control_period_s"] = s.control_period;
  j["controller"] = controller_text(s);
  j["method"] = "stepped sines: per frequency a reference run and a disturbance run from the initial state; the first "
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
  j["closed_loop_peak_db"] = num(r.peak_db);
  j["closed_loop_peak_hz"] = num(r.peak_hz);
  j["sensitivity_peak"] = num(r.sensitivity_peak);
  j["sensitivity_peak_hz"] = num(r.sensitivity_peak_hz);
  j["phase_margin_deg"] = num(r.phase_margin_deg);
  j["crossover_hz"] = num(r.crossover_hz);
  j["gain_margin_db"] = num(r.gain_margin_db);
  j["phase_crossover_hz"] = num(r.phase_crossover_hz);
  j["min_dynamic_stiffness_N_per_um"] = num(r.min_stiffness_N_per_um);
  j["min_dynamic_stiffness_hz"] = num(r.min_stiffness_hz);
  const std::string doubtful = doubtful_points(r);
  j["doubtful_frequencies_hz"] = doubtful.empty() ? nlohmann::ordered_json() : nlohmann::ordered_json(doubtful);
  j["wall_time_s"] = r.wall_time_s;
  folder.write_text("frequency_response.json", j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  std::string plot_error;
  if (plots && !r.points.empty()) {
    const bool a = r.points.front().has_reference, d = r.points.front().has_disturbance;
    std::ostringstream gp;
    gp << "data = 'frequency_response.csv'\nset logscale x\nset xlabel 'f [Hz]'\nset datafile missing 'nan'\n";
    if (a) {
      gp << "set output 'bode_reference.png'\nset multiplot layout 2,1 title " << output::gnuplot_string(s.name + ": reference -> position T, amplitude min(" + g(o.reference_amplitude) + " m, " +
                                   g(r.acceleration_limit) + " m/s^2 / w^2)")
         << "\nset ylabel '|T| [dB]'\nplot data using 1:3 with linespoints title '|T|', -3.01 with lines dt 2 title '-3 dB'\n"
         << "set ylabel 'arg T [deg]'\nplot data using 1:4 with linespoints title 'arg T'\nunset multiplot\n";
    }
    if (d) {
      gp << "set output 'bode_compliance.png'\nset multiplot layout 2,1 title " << output::gnuplot_string(s.name + ": dynamic stiffness 1/|x/F_d|, force " + g(o.force_amplitude) + " N")
         << "\nset logscale y\nset ylabel 'dynamic stiffness [N/um]'\nplot data using 1:7 with linespoints title 'k_dyn'\n"
         << "unset logscale y\nset ylabel 'arg x/F_d [deg]'\nplot data using 1:6 with linespoints title 'arg G_d'\nunset multiplot\n";
      gp << "set output 'bode_loop.png'\nset multiplot layout 2,1 title " << output::gnuplot_string(s.name + ": loop at the force set-point, force " + g(o.force_amplitude) + " N")
         << "\nset ylabel 'magnitude [dB]'\nplot data using 1:8 with linespoints title '|L|', '' using 1:10 with linespoints "
            "title '|S|', 0 with lines dt 2 notitle\n"
         << "set ylabel 'arg L [deg]'\nplot data using 1:9 with linespoints title 'arg L', -180 with lines dt 2 notitle\n"
            "unset multiplot\n";
    }
    try {
      folder.plot(gp.str(), stop);
    } catch (const std::runtime_error& e) {
      plot_error = e.what();
    }
  }
  folder.commit();
  return plot_error;
}

}  // namespace feeddrive::analysis
