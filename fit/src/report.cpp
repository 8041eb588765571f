#include "feeddrive/fit/report.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "feeddrive/common/text_file.hpp"
#include "feeddrive/output/csv.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/output/gnuplot.hpp"
#include "feeddrive/plant/effects.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/yaml_reader.hpp"

namespace feeddrive::fit {
namespace fs = std::filesystem;

std::string fitted_scenario_yaml(const std::string& scenario_path, const plant::PlantParams& fitted) {
  // The one YAML loader (its checks: recursive aliases, merge keys, duplicate keys, size).
  YAML::Node root = sim::load_yaml_strict(text::read_text_file<sim::ScenarioError>(scenario_path, "scenario file"));
  const fs::path base = fs::absolute(scenario_path).parent_path();
  for (const auto& [section, key] : sim::file_keys()) {  // the file names, valid from the output folder
    if (!root[section].IsMap() || !root[section][key].IsScalar()) continue;
    const fs::path f = root[section][key].Scalar();
    if (f.is_relative()) root[section][key] = (base / f).lexically_normal().string();
  }
  if (!root["plant"]) root["plant"] = YAML::Node(YAML::NodeType::Map);
  YAML::Node effects = root["plant"]["effects"];
  for (const Effect& e : plant::enabled_effects(fitted.effects)) {
    YAML::Node m(YAML::NodeType::Map);
    for (const auto& [k, v] : e.parameters) m[k] = v;
    effects[e.name] = m;
  }
  root["plant"]["effects"] = effects;
  // the model-form parameter the fit refits with any Coulomb-type term (workflow.hpp)
  if (has_coulomb_term(fitted)) {
    if (!root["plant"]["friction"]) root["plant"]["friction"] = YAML::Node(YAML::NodeType::Map);
    root["plant"]["friction"]["static_smoothing_velocity"] = fitted.friction.static_smoothing_velocity;
    root["plant"]["friction"]["static_smoothing_shape"] = fitted.friction.static_smoothing_shape;
  }
  if (has_stribeck_hump(fitted)) {
    if (!root["plant"]["friction"]) root["plant"]["friction"] = YAML::Node(YAML::NodeType::Map);
    root["plant"]["friction"]["stribeck_exponent"] = fitted.friction.stribeck_exponent;
  }
  YAML::Emitter em;
  em.SetDoublePrecision(15);
  em << root;
  std::string shown_path = scenario_path;  // a comment: one line, whatever the path holds
  for (char& c : shown_path)
    if (c == '\n' || c == '\r') c = '?';
  return std::string("# feeddrive-fit: ") + shown_path + " plus the fitted effects under plant.effects\n" + em.c_str() +
         "\n";
}

namespace {

nlohmann::json params_json(const Effect& e) {
  nlohmann::json p = nlohmann::json::object();
  for (const auto& [k, v] : e.parameters) p[k] = v;
  return p;
}

// The parameters' units (the names carry none: plant::effect_parameter_unit, the effect's list).
nlohmann::json units_json(const Effect& e) {
  nlohmann::json u = nlohmann::json::object();
  for (const auto& [k, v] : e.parameters) u[k] = plant::effect_parameter_unit(e.name, k);
  return u;
}

// " N" after a value of parameter k of e; "" for a number without unit.
std::string unit_suffix(const Effect& e, const std::string& k) {
  const std::string& u = plant::effect_parameter_unit(e.name, k);
  return u == "-" ? std::string() : " " + u;
}

nlohmann::json bins_json(const std::vector<Bin>& bins) {
  nlohmann::json a = nlohmann::json::array();
  for (const Bin& b : bins)
    a.push_back({{"bin", b.label},
                 {"points", b.points},
                 {"force_rms_N", b.force_rms},
                 {"share", b.share},
                 {"concentration", b.concentration},
                 {"gap_m", b.gap}});
  return a;
}

// The 95 % half-widths of one group of r.ci95 (an effect's parameters, or "model_form"): a number,
// or "undetermined" (NaN: e.g. the phase of a vanishing amplitude).
nlohmann::json ci_json(const FitResult& r, const std::string& group) {
  nlohmann::json ci = nlohmann::json::object();
  if (const auto it = r.ci95.find(group); it != r.ci95.end())
    for (const auto& [k, v] : it->second) ci[k] = std::isfinite(v) ? nlohmann::json(v) : nlohmann::json("undetermined");
  return ci;
}

// A named effect of findings.json: its final (jointly refitted) parameters with their 95 %
// intervals ("undetermined" where not finite), any caveat, and the evidence of the step that
// brought it in: the step that added it, or the one whose swap move turned an earlier effect into it.
nlohmann::json effect_json(const FitResult& r, const Effect& final) {
  const StepResult* from = nullptr;
  for (const StepResult& st : r.steps) {
    if (!st.accepted) continue;
    const std::string into = st.swap.empty() ? "" : st.swap.substr(st.swap.rfind(' ') + 1);
    if (st.effect.name == final.name || into == final.name) from = &st;
  }
  const nlohmann::json ci = ci_json(r, final.name);
  const auto tent = r.tentative.find(final.name);
  nlohmann::json e = {{"name", final.name},
                      {"parameters", params_json(final)},
                      {"units", units_json(final)},
                      {"ci95", ci},
                      {"tentative", tent != r.tentative.end()},
                      {"caveat", tent != r.tentative.end() ? tent->second : std::string()}};
  if (from) {
    e["score"] = from->score;
    e["gap_before"] = from->gap_before;
    e["gap_after"] = from->gap_after;
  }
  return e;
}

// findings.json's "noise_floor" (verdict.hpp).
nlohmann::json floor_json(const NoiseFloor& f) {
  return {{"gap_m", f.gap},
          {"force_rms_N", f.force},
          {"quantization_m", f.quantization},
          {"quantization_given_m", f.quantization_given > 0 ? f.quantization_given : f.quantization},
          {"noise_m", f.noise},
          {"noise_given_m", f.noise_given > 0 ? f.noise_given : f.noise},
          {"position_sigma_m", f.position},
          {"gap_factor", f.gap_factor},
          {"force_factor", f.force_factor},
          {"from_scenario", f.from_scenario},
          {"source", f.source},
          {"force_noise_N", f.force_noise},
          {"force_discretisation_N", f.force_discretisation},
          {"stamp_error_s", f.stamp_error},
          {"stamp_error_given_s", f.stamp_given > 0 ? f.stamp_given : f.stamp_error},
          {"replay_window_s", f.window},
          {"filter_half_width_s", f.half_width},
          {"detection_limit_N", f.limit},
          {"detection_limit_gap_N", f.limit_gap},
          {"detection_limit_force_N", f.limit_force},
          {"detection_limit_default_N", f.limit_default}};
}

// findings.json's "record": what the record spans (the plausibility rules' envelope).
nlohmann::json envelope_json(const Envelope& env) {
  return {{"travel_m", env.travel},
          {"peak_speed_mps", env.v_max},
          {"peak_thrust_N", env.peak_thrust},
          {"ripple_pitch_range_m", {env.min_pitch(), env.max_pitch()}},
          {"stick_phases", env.stick_phases},
          {"reversals", env.reversals},
          {"stick_fraction", env.stick_fraction}};
}

// One step of findings.json's "steps": its decision, the ranking of the candidates, the
// out-of-sample evidence and where the residual was before it.
nlohmann::json step_json(const StepResult& st) {
  nlohmann::json rk = nlohmann::json::array();
  for (const CandidateFit& c : st.ranking)
    rk.push_back({{"name", c.effect.name},
                  {"score", std::isfinite(c.score) ? nlohmann::json(c.score) : nlohmann::json()},
                  {"parameters", params_json(c.effect)},
                  {"k", c.parameters},
                  {"rss_N2", c.rss},
                  {"passed_over", c.passed_over},
                  {"tentative", c.tentative},
                  {"swap", c.swap},
                  {"fit_seconds", c.seconds}});
  return {{"accepted", st.accepted},
          {"verdict", st.verdict},
          {"gap_before_m", st.gap_before},
          {"gap_after_m", st.accepted ? st.gap_after : st.gap_before},  // a step that adds nothing keeps it
          {"ranking", rk},
          {"removed", st.removed},
          {"swap", st.swap},
          {"caveat", st.caveat},
          {"ties", st.ties},
          {"cross_validation",
           {{"held_out_sq_residual_without_N2", st.cv_without}, {"held_out_sq_residual_with_N2", st.cv_with}}},
          {"localisation",
           {{"summary", st.localisation.summary},
            {"time", bins_json(st.localisation.time)},
            {"velocity", bins_json(st.localisation.velocity)},
            {"acceleration", bins_json(st.localisation.acceleration)},
            {"position", bins_json(st.localisation.position)}}}};
}

}  // namespace

std::string findings_json(const FitResult& r, const MeasuredData* data) {
  nlohmann::json j;
  if (data != nullptr)
    j["data"] = {{"source", data->source},
                 {"samples", data->size()},
                 {"time_offset_s", data->time_offset},
                 {"notes", data->notes}};
  j["gap_initial"] = r.replay_initial.gap;
  j["gap_final"] = r.replay_final.gap;
  j["gap_unit"] = "m";
  j["force_residual_rms_initial_N"] = r.force_rms_initial;
  j["force_residual_rms_final_N"] = r.force_rms_final;
  j["effects"] = nlohmann::json::array();
  for (const Effect& final : r.effects) j["effects"].push_back(effect_json(r, final));
  j["verdict"] = verdict_name(r.verdict);
  j["exit_code"] = exit_code(r.verdict);
  j["noise_floor"] = floor_json(r.floor);
  j["unexplained"] = r.unexplained;
  j["ties"] = r.ties;
  j["unconfirmed"] = r.unconfirmed;
  j["conclusion"] = r.conclusion;
  j["model_form"] = {{"coulomb_transition_velocity_initial_mps", r.smoothing_initial},
                     {"coulomb_transition_velocity_final_mps", r.smoothing_final},
                     {"coulomb_transition_shape_initial", r.shape_initial},
                     {"coulomb_transition_shape_final", r.shape_final},
                     {"stribeck_exponent_initial", r.exponent_initial},
                     {"stribeck_exponent_final", r.exponent_final},
                     {"direction_asymmetry_N", r.asymmetry_offset},
                     {"fitted", r.smoothing_fitted},
                     {"ci95", ci_json(r, "model_form")}};
  j["record"] = envelope_json(r.envelope);
  nlohmann::json steps = nlohmann::json::array();
  for (const StepResult& st : r.steps) steps.push_back(step_json(st));
  j["steps"] = steps;
  // A path that is not UTF-8 (the name is checked at load time) is written with U+FFFD, never an
  // exception after the run.
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

namespace {

std::string table(const std::vector<Bin>& bins) {
  std::ostringstream s;
  s << "| bin | points | force RMS [N] | share of residual | concentration | replay gap [um] "
       "|\n|---|---|---|---|---|---|\n";
  char buf[256];
  for (const Bin& b : bins) {
    std::snprintf(buf, sizeof buf, "| %s | %ld | %.3g | %.1f %% | %.2f | %.3g |\n", b.label.c_str(), b.points,
                  b.force_rms, 100 * b.share, b.concentration, b.gap * 1e6);
    s << buf;
  }
  return s.str();
}

std::string params_text(const Effect& e) {
  std::string s;
  char buf[96];
  for (const auto& [k, v] : e.parameters) {
    std::snprintf(buf, sizeof buf, "%s%s = %.6g%s", s.empty() ? "" : ", ", k.c_str(), v, unit_suffix(e, k).c_str());
    s += buf;
  }
  return s;
}

// replay.csv: the measured position, the replays of the model as given and of the fitted model,
// and their errors, per sample (the data behind replay.png).
void write_replay_csv(const output::StagedFolder& out, const MeasuredData& d, const FitResult& r) {
  output::CsvWriter f(out.path("replay.csv"),
                      {"t", "x", "x_sim_initial", "x_sim_final", "error_initial", "error_final"});
  for (std::size_t k = 0; k < d.size(); ++k)
    f.row({d.t[k], d.x[k], r.replay_initial.x_sim[k], r.replay_final.x_sim[k], r.replay_initial.error[k],
           r.replay_final.error[k]});
  f.close();
}

// gap.csv: the replay gap and force residual RMS of the model as given and after each addition.
void write_gap_csv(const output::StagedFolder& out, const FitResult& r) {
  std::ofstream f(out.path("gap.csv"));
  f << "step,label,gap_m,force_rms_N\n";
  f << "0,initial," << r.replay_initial.gap << ',' << r.force_rms_initial << '\n';
  int k = 1;
  for (const StepResult& st : r.steps)
    if (st.accepted) f << k++ << ",+" << st.effect.name << ',' << st.gap_after << ',' << st.force_rms_after << '\n';
}

// effectK.csv for the K-th addition: the filtered force residual before and after it, and the
// effect's own filtered force, against the effect's regressor.
void write_effect_csvs(const output::StagedFolder& out, const Record& rec, const FitResult& r) {
  int n_eff = 0;
  for (const StepResult& st : r.steps) {
    if (!st.accepted) continue;
    ++n_eff;
    const auto [label, xs] = effect_regressor(rec, st.effect);
    output::CsvWriter f(out.path("effect" + std::to_string(n_eff) + ".csv"),
                        {"regressor", "residual_before", "effect_force", "residual_after"});
    for (std::size_t i = 0; i < xs.size(); ++i) {
      const long li = static_cast<long>(i);
      // r = -filtered F_extra: the effect's own filtered force is -(r_after - r_before)
      f.row(
          {xs[i], -st.residual_before[li], -(st.residual_before[li] - st.residual_after[li]), -st.residual_after[li]});
    }
    f.close();
  }
}

// report.md's head: the inputs, the verdict and the gap after each step.
void md_head(std::ostringstream& md, const std::string& scenario_path, const Record& rec, const FitResult& r) {
  const MeasuredData& d = *rec.data;
  char buf[512];
  md << "# feeddrive-fit report\n\n"
     << "- model: `" << scenario_path << "`\n- data: `" << d.source << "` (" << d.size() << " samples, "
     << d.t.back() - d.t.front() << " s, median period " << rec.period * 1e3 << " ms)\n"
     << "- filter half-width L = " << rec.bank.half_width * 1e3 << " ms, " << rec.bank.tau.size()
     << " independent force-residual points\n";
  for (const std::string& n : d.notes) md << "- data note: " << n << "\n";
  md << "\n"
     << "**Verdict: " << verdict_name(r.verdict) << "** (exit code " << exit_code(r.verdict) << ")\n\n"
     << "**" << r.conclusion << "**\n\n"
     << "The gap is the RMS position error of the model replayed from the measured state over windows "
        "(docs/fit.md); the force measure is the RMS of the filtered force residual.\n\n"
     << "## Gap after each step\n\n| step | model | gap [um] | force residual RMS [N] |\n|---|---|---|---|\n";
  std::snprintf(buf, sizeof buf, "| 0 | as given | %.4g | %.4g |\n", r.replay_initial.gap * 1e6, r.force_rms_initial);
  md << buf;
  int k = 0;
  for (const StepResult& st : r.steps) {
    if (!st.accepted) continue;
    const std::string label = st.effect.name + (st.swap.empty() ? "" : " (swap: " + st.swap + ")") +
                              (st.caveat.empty() ? "" : " (tentative)");
    std::snprintf(buf, sizeof buf, "| %d | + %s | %.4g | %.4g |\n", ++k, label.c_str(), st.gap_after * 1e6,
                  st.force_rms_after);
    md << buf;
  }
}

// report.md: the noise floor, and a "## title" section with one item per line (none if empty).
void md_floor(std::ostringstream& md, const NoiseFloor& f) {
  char a[160], b[600];
  std::snprintf(a, sizeof a, "\nNoise floor: gap %.3g um, force residual %.3g N RMS (sigma_x = %.3g nm; ", f.gap * 1e6,
                f.force, f.position * 1e9);
  std::snprintf(
      b, sizeof b,
      "; force: %.3g N of the sensor and stamps, %.3g N of the filter's discretisation); \"within\" means at "
      "most %.3gx the force floor (friction changing sign within a sample at reversals) and %.3gx the gap floor "
      "(the replay's unobserved friction state and fitted parameters' drift).\n\n",
      f.force_noise, f.force_discretisation, f.force_factor, f.gap_factor);
  md << a << f.source << b;
  char c[240], d[120] = "";
  std::snprintf(c, sizeof c,
                "Detection limit: the smallest constant force this record shows at W = %.3g s, L = %.3g ms is %.3g N "
                "(by the gap %.3g N, by the force residual %.3g N)",
                f.window, f.half_width * 1e3, f.limit, f.limit_gap, f.limit_force);
  if (f.limit_default > 0 && (f.window_default != f.window || f.half_width_default != f.half_width))
    std::snprintf(d, sizeof d, "; at the defaults (W = %.3g s, L = %.3g ms) %.3g N", f.window_default,
                  f.half_width_default * 1e3, f.limit_default);
  md << c << d << ".\n\n";
}
void md_list(std::ostringstream& md, const char* title, const std::vector<std::string>& items) {
  if (items.empty()) return;
  md << "## " << title << "\n\n";
  for (const std::string& u : items) md << "- " << u << "\n";
  md << "\n";
}

// report.md: the named effects with their parameters and 95 % intervals, and the model form.
void md_effects(std::ostringstream& md, const FitResult& r) {
  char buf[512];
  md << "\n## Effects found\n\n";
  if (r.effects.empty()) md << "None named: each step above says why each candidate was passed over.\n";
  for (const Effect& e : r.effects) {
    md << "- `" << e.name << "`" << (r.tentative.count(e.name) ? " (**tentative**)" : "") << ": ";
    std::string sep;
    for (const auto& [k, v] : e.parameters) {
      double w = std::nan("");
      if (const auto it = r.ci95.find(e.name); it != r.ci95.end() && it->second.count(k)) w = it->second.at(k);
      const std::string u = unit_suffix(e, k);
      if (std::isfinite(w))
        std::snprintf(buf, sizeof buf, "%s%s = %.6g +- %.2g%s", sep.c_str(), k.c_str(), v, w, u.c_str());
      else
        std::snprintf(buf, sizeof buf, "%s%s = %.6g%s (interval undetermined)", sep.c_str(), k.c_str(), v, u.c_str());
      md << buf;
      sep = ", ";
    }
    md << " (95 % intervals)\n";
    if (r.tentative.count(e.name)) md << "  - caveat: " << r.tentative.at(e.name) << "\n";
  }
  if (r.smoothing_final != r.smoothing_initial || r.shape_final != r.shape_initial) {
    std::snprintf(
        buf, sizeof buf,
        "\nModel form (not an effect): the Coulomb transition of sgn_eps(v) = (1 - b) tanh(v/eps) + "
        "b v/sqrt(v^2 + eps^2) was refitted: eps %.3g -> %.3g mm/s (plant.friction.static_smoothing_velocity), "
        "b %.2g -> %.2g (plant.friction.static_smoothing_shape).\n",
        r.smoothing_initial * 1e3, r.smoothing_final * 1e3, r.shape_initial, r.shape_final);
    md << buf;
  }
  if (r.exponent_final != r.exponent_initial) {
    std::snprintf(buf, sizeof buf,
                  "\nModel form (not an effect): the Stribeck exponent delta of exp(-|v/vs|^delta) was refitted: "
                  "%.3g -> %.3g (plant.friction.stribeck_exponent).\n",
                  r.exponent_initial, r.exponent_final);
    md << buf;
  }
}

// report.md: what the record spans (the plausibility rules' envelope).
void md_envelope(std::ostringstream& md, const Envelope& env) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "\nWhat this record can show (plausibility rules, docs/fit.md): travel %.4g mm, peak speed %.4g "
                "mm/s, peak thrust %.4g N; ripple pitches %.3g-%.3g mm; %d stick phases (%.2g %% of the samples "
                "below %.3g mm/s), %d reversals.\n",
                env.travel * 1e3, env.v_max * 1e3, env.peak_thrust, env.min_pitch() * 1e3, env.max_pitch() * 1e3,
                env.stick_phases, 100 * env.stick_fraction, env.stick_velocity * 1e3, env.reversals);
  md << buf;
}

// report.md: step s (from 0) with its verdict, out-of-sample evidence, ranking and where the
// residual was; `plot` the number of its effect plot (0: none).
void md_step(std::ostringstream& md, std::size_t s, const StepResult& st, int plot) {
  char buf[512];
  md << "\n## Step " << s + 1 << ": " << st.verdict << "\n\n" << st.localisation.summary << ".\n\n";
  if (!st.cv_with.empty()) {
    double a = 0, b = 0;
    for (double v : st.cv_without) a += v;
    for (double v : st.cv_with) b += v;
    std::snprintf(buf, sizeof buf,
                  "Out of sample (%zu blocks of time, each predicted by a fit to the others): held-out squared "
                  "force residual %.4g -> %.4g N^2.\n\n",
                  st.cv_with.size(), a, b);
    md << buf;
  }
  md << "Candidates (score = BIC of the model - BIC of the model with the effect, every free parameter "
        "refitted jointly; significant above the threshold):\n\n"
     << "| rank | effect | score | k | parameters | passed over because |\n|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < st.ranking.size(); ++i) {
    std::snprintf(buf, sizeof buf, "| %zu | %s | %.4g | %d | ", i + 1, st.ranking[i].effect.name.c_str(),
                  st.ranking[i].score, st.ranking[i].parameters);
    md << buf << params_text(st.ranking[i].effect) << " | " << st.ranking[i].passed_over << " |\n";
  }
  md << "\nWhere the residual was (before this step):\n\n"
     << "Velocity regimes\n\n"
     << table(st.localisation.velocity) << "\nAcceleration phases\n\n"
     << table(st.localisation.acceleration) << "\nPosition\n\n"
     << table(st.localisation.position) << "\nTime\n\n"
     << table(st.localisation.time);
  if (plot > 0) md << "\n![residual against the regressor of " << st.effect.name << "](effect" << plot << ".png)\n";
}

// report.md: the whole report.
std::string report_md(const std::string& scenario_path, const Record& rec, const FitResult& r, bool plots) {
  std::ostringstream md;
  md_head(md, scenario_path, rec, r);
  if (plots) md << "\n![gap after each step](gap.png)\n\n![measured and replayed](replay.png)\n";
  md_floor(md, r.floor);
  md_list(md, "Unexplained discrepancy", r.unexplained);
  md_list(md, "Ties", r.ties);
  md_list(md, "Named in a step, removed by the final confirmation", r.unconfirmed);
  md_effects(md, r);
  md_envelope(md, r.envelope);
  int k = 0;
  for (std::size_t s = 0; s < r.steps.size(); ++s) {
    const bool plot = r.steps[s].accepted && plots;
    md_step(md, s, r.steps[s], plot ? ++k : 0);
  }
  return md.str();
}

// The gnuplot script of replay.png, gap.png and effectK.png (fixed data file names; every other
// text through output::gnuplot_string).
std::string plot_script(const Record& rec, const FitResult& r) {
  std::ostringstream gp;
  gp << "set output 'replay.png'\nset multiplot layout 2,1 title 'measured vs replayed model (windows restart "
        "from the measured state)'\nset xlabel 't [s]'\nset ylabel 'x [mm]'\n"
     << "plot 'replay.csv' every ::1 using 1:($2*1e3) with lines lw 2 title 'measured', '' every ::1 using "
        "1:($3*1e3) with lines title 'model as given', '' every ::1 using 1:($4*1e3) with lines title 'fitted "
        "model'\n"
     << "set ylabel 'x_sim - x [um]'\nplot 'replay.csv' every ::1 using 1:($5*1e6) with lines title 'model as "
        "given', '' every ::1 using 1:($6*1e6) with lines title 'fitted model'\nunset multiplot\n";
  gp << "set output 'gap.png'\nset title 'replay gap after each step'\nset xlabel 'step'\nset ylabel 'gap [um]'\n"
     << "set logscale y\nset style fill solid 0.5\nset boxwidth 0.6\nunset key\n"
     << "plot 'gap.csv' every ::1 using 1:($3*1e6):xtic(2) with boxes\nunset logscale y\nset key\n";
  int k = 0;
  for (const StepResult& st : r.steps) {
    if (!st.accepted) continue;
    ++k;
    const auto label = effect_regressor(rec, st.effect).first;
    gp << "set output 'effect" << k << ".png'\nset title "
       << output::gnuplot_string("step " + std::to_string(k) + ": " + st.effect.name +
                                 " -- filtered force residual against its regressor")
       << "\nset xlabel " << output::gnuplot_string(label) << "\nset ylabel 'force [N]'\nplot 'effect" << k
       << ".csv' every ::1 using 1:2 with points pt 7 ps 0.4 title 'residual before (-r)', '' every ::1 using "
          "1:3 with points pt 7 ps 0.4 title 'fitted effect (filtered)', '' every ::1 using 1:4 with points pt 7 "
          "ps 0.3 title 'residual after'\n";
  }
  return gp.str();
}

}  // namespace

std::vector<std::string> write_outputs(const std::string& out_dir, const std::string& scenario_path, const Record& rec,
                                       const FitResult& r, bool plots, const interrupt::StopToken& stop) {
  output::StagedFolder out(out_dir, "feeddrive-fit");
  out.write_text("findings.json", findings_json(r, rec.data));
  out.write_text("model.fitted.yaml", fitted_scenario_yaml(scenario_path, r.fitted));
  write_replay_csv(out, *rec.data, r);
  write_gap_csv(out, r);
  write_effect_csvs(out, rec, r);
  out.write_text("report.md", report_md(scenario_path, rec, r, plots));
  if (plots) out.plot(plot_script(rec, r), stop);
  return out.commit();
}

std::string result_table(const FitResult& r, const std::string& out_dir) {
  char buf[512];
  std::string s;
  std::snprintf(buf, sizeof buf, "%-4s %-24s %14s %18s\n", "step", "model", "gap [um]", "force RMS [N]");
  s += buf;
  std::snprintf(buf, sizeof buf, "%-4d %-24s %14.4g %18.4g\n", 0, "as given", r.replay_initial.gap * 1e6,
                r.force_rms_initial);
  s += buf;
  int k = 0;
  for (const auto& st : r.steps) {
    if (!st.accepted) continue;
    std::snprintf(buf, sizeof buf, "%-4d %-24s %14.4g %18.4g", ++k, ("+ " + st.effect.name).c_str(), st.gap_after * 1e6,
                  st.force_rms_after);
    s += buf + (st.swap.empty() ? "" : "   (swap: " + st.swap + ")") + "\n";
  }
  s += r.conclusion + "\n";
  for (const auto& [name, caveat] : r.tentative) s += "tentative " + name + ": " + caveat + "\n";
  for (const std::string& t : r.ties) s += "tie: " + t + "\n";
  for (const std::string& u : r.unconfirmed) s += "removed by the final confirmation: " + u + "\n";
  for (const std::string& u : r.unexplained) s += "  " + u + "\n";
  return s + "results: " + out_dir + "/{findings.json,model.fitted.yaml,report.md}\n";
}

}  // namespace feeddrive::fit
