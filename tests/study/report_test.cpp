// The study's outcome and report (issue 23, review findings F3-F6, F22): a case's loader warnings
// and move_finished reach results.csv and report.md (and survive the case file), time keys are
// shown in ms or us with their unit, a key with text values (switching: sgn, tanh) gets a table by
// value and a plot with categories, a log-spaced sweep gets a log x-axis, the y-label is the
// metric's name without its SI suffix, and the tables' note counts the cases per value.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "../support/scratch.hpp"
#include "feeddrive/study/cases.hpp"
#include "feeddrive/study/report.hpp"
#include "feeddrive/study/runner.hpp"
#include "feeddrive/study/spec.hpp"
#include "study_util.hpp"

namespace feeddrive::study {
namespace {

namespace fs = std::filesystem;

const std::string kScenario = test::scenarios() + "/smc_bl_jerk_limited.yaml";

Study sweep(const std::vector<std::string>& sweeps) {
  std::vector<GridAxis> axes;
  for (const std::string& s : sweeps) axes.push_back(parse_sweep(s));
  return sweep_study(kScenario, axes);
}

// The report data of `s` with every case resolved by the real resolver and given the outcome
// `outcome(i)` (the report's logic is under test here, not the runs: StudyOutcome runs one).
template <class F>
std::string report_of(const Study& s, ReportData& d, F&& outcome) {
  Resolver r(s);
  for (std::size_t i = 0; i < case_count(s); ++i) {
    CaseRecord c;
    c.spec = case_at(s, i);
    c.resolved = r.resolve(c.spec);
    c.outcome = outcome(i);
    d.add(i, c);
  }
  return report_md(d, "feeddrive-study test", "");
}

Outcome ok_with(double error_m) {
  Outcome o;
  o.ok = true;
  o.metrics = {{"position_error_max_abs_m", error_m}};
  return o;
}

// The gnuplot script write_plots writes into `dir` (before gnuplot runs: a machine without
// gnuplot throws after it is written).
std::string plot_script(const fs::path& dir, const ReportData& d) {
  try {
    write_plots(dir, "plots/", d);
  } catch (const std::runtime_error&) {}
  return test_support::slurp(dir / "plots.gp");
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(StudyOutcome, ACaseCarriesItsLoaderWarningsAndWhetherItsMoveFinished) {
  // F3: max_velocity 500 (mm/s meant) and a run of 10 ms, far shorter than the move (about a
  // second): both are warnings of the loader, and the move does not finish.
  const Study s = sweep({"reference.max_velocity=0.2,500"});
  Study st = s;
  st.set.push_back({"duration", "0.01"});
  Resolver r(st);
  const Outcome o = run_case(*r.resolve(case_at(st, 1)).scenario);
  ASSERT_TRUE(o.ok) << o.error;
  ASSERT_TRUE(o.move_finished.has_value());
  EXPECT_FALSE(*o.move_finished);
  const auto found = [&](const std::string& part) {
    return std::any_of(o.warnings.begin(), o.warnings.end(), [&](const std::string& w) { return has(w, part); });
  };
  EXPECT_TRUE(found("reference.max_velocity: 500 m/s")) << ::testing::PrintToString(o.warnings);
  EXPECT_TRUE(found("the run cuts it off")) << ::testing::PrintToString(o.warnings);

  // The case file keeps both; a case file of format 1 (before them) is not reused.
  const std::string json = outcome_json("h", o);
  const auto back = parse_outcome(json, "h");
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->warnings, o.warnings);
  EXPECT_EQ(back->move_finished, o.move_finished);
  Outcome no_move = ok_with(1e-6);  // not a move: null, read back as no value
  const auto nm = parse_outcome(outcome_json("h", no_move), "h");
  ASSERT_TRUE(nm.has_value());
  EXPECT_FALSE(nm->move_finished.has_value());
  std::string old = json;
  old.replace(old.find("\"format\": 2"), 11, "\"format\": 1");
  EXPECT_FALSE(parse_outcome(old, "h").has_value()) << old;
}

TEST(StudyReport, WarningsOnceWithTheirCountAndTheCasesWhoseMoveWasCutOff) {
  const Study s = sweep({"plant.mass=80,100,120"});
  ReportData d(s);
  const std::string md = report_of(s, d, [](std::size_t i) {
    Outcome o = ok_with(1e-6);
    o.move_finished = i == 0;
    if (i > 0) o.warnings = {"reference: cut off", i == 1 ? "a: one" : "b: other"};
    return o;
  });
  EXPECT_EQ(d.moves, 3u);
  EXPECT_EQ(d.moves_unfinished, 2u);
  EXPECT_TRUE(has(md, "**2 of 3 cases did not finish their move**")) << md;
  EXPECT_TRUE(has(md, "- reference: cut off (2 of 3 cases)")) << md;
  EXPECT_TRUE(has(md, "- a: one (1 of 3 cases)")) << md;
  EXPECT_EQ(warning_lines(d).size(), 3u);
}

TEST(StudyReport, TimeKeysAreShownInMicrosecondsOrMillisecondsWithTheirUnit) {
  // F4: control_period and computation_delay are read outside the params lists; their values
  // were shown as 0.0001 without a unit.
  const Study s = sweep({"control_period=1e-4,2e-4", "controller.computation_delay=0,1e-4"});
  ReportData d(s);
  const std::string md = report_of(s, d, [](std::size_t i) { return ok_with(1e-6 * static_cast<double>(i + 1)); });
  EXPECT_TRUE(has(md, "| control_period [us] |")) << md;
  EXPECT_TRUE(has(md, "| controller.computation_delay [us] |")) << md;
  for (const char* row : {"| 100 |", "| 200 |", "| 0 |"}) EXPECT_TRUE(has(md, row)) << row << "\n" << md;
  // F22: a grid of two keys has two cases per value of each: the note says so.
  EXPECT_TRUE(has(md, "(2 each, over the values of the other varied keys")) << md;
  EXPECT_FALSE(has(md, "one-key sweep")) << md;

  const Study t = sweep({"duration=0.01,0.5"});
  ReportData e(t);
  const std::string mt = report_of(t, e, [](std::size_t) { return ok_with(1e-6); });
  EXPECT_TRUE(has(mt, "| duration [ms] |")) << mt;
  EXPECT_TRUE(has(mt, "| 10 |")) << mt;
  EXPECT_TRUE(has(mt, "| 500 |")) << mt;
  EXPECT_TRUE(has(mt, "One case per value and controller.")) << mt;
}

TEST(StudyReport, AKeyWithTextValuesGetsATableAndAPlotByCategory) {
  // F5: switching sgn, tanh once gave "No numeric value of this key." and no plot.
  const Study s = sweep({"controller.switching=sgn,tanh"});
  ReportData d(s);
  const std::string md = report_of(s, d, [](std::size_t i) { return ok_with(i == 0 ? 2e-6 : 1e-6); });
  EXPECT_TRUE(has(md, "| controller.switching |")) << md;
  EXPECT_TRUE(has(md, "| sgn | 2 |")) << md;
  EXPECT_TRUE(has(md, "| tanh | 1 |")) << md;
  const fs::path dir = test_support::make_scratch("study-report-cat");
  const std::string gp = plot_script(dir, d);
  EXPECT_TRUE(has(gp, "set xtics (\"sgn\" 1, \"tanh\" 2)")) << gp;
  EXPECT_TRUE(has(gp, "'param_0_0.dat'")) << gp;
  // F22: the y-label is the metric's name without _m, with the unit shown.
  EXPECT_TRUE(has(gp, "set ylabel \"position_error_max_abs [um]\"")) << gp;
  EXPECT_EQ(test_support::slurp(dir / "param_0_0.dat"), "1 2\n2 1\n");
}

TEST(StudyReport, ALogSweepIsPlottedOnALogAxis) {
  // F6: given log-spaced, or positive over more than two decades.
  const Study s = sweep({"plant.sensor.quantization=log:1e-9:1e-6:3"});
  EXPECT_TRUE(log_axis(s, "plant.sensor.quantization", {0.001, 0.0316, 1}));
  const Study lin = sweep({"plant.mass=1:1000:3"});
  EXPECT_TRUE(log_axis(lin, "plant.mass", {1, 500.5, 1000}));  // three decades
  EXPECT_FALSE(log_axis(lin, "plant.mass", {80, 100, 120}));   // a fraction of one
  EXPECT_FALSE(log_axis(lin, "plant.mass", {0, 100, 1000}));   // 0 has no logarithm
  ReportData d(s);
  report_of(s, d, [](std::size_t) { return ok_with(1e-6); });
  const std::string gp = plot_script(test_support::make_scratch("study-report-log"), d);
  EXPECT_TRUE(has(gp, "set logscale x\n")) << gp;
  EXPECT_TRUE(has(gp, "set xlabel \"plant.sensor.quantization [um]\"")) << gp;
}

TEST(StudyReport, TheMetricsLabelDropsItsSiSuffix) {
  EXPECT_EQ(metric_label("position_error_max_abs_m", "um"), "position_error_max_abs [um]");
  EXPECT_EQ(metric_label("settling_time_s", "ms"), "settling_time [ms]");
  EXPECT_EQ(metric_label("final_velocity_mps", "mm/s"), "final_velocity [mm/s]");
  EXPECT_EQ(metric_label("overshoot_percent", "%"), "overshoot_percent [%]");
  EXPECT_EQ(metric_label("control_saturated_steps", ""), "control_saturated_steps");
}

}  // namespace
}  // namespace feeddrive::study
