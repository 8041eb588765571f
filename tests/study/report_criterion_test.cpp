// The report's pass criterion (report.limit and report.require, docs/study.md): a case passes
// only when its metric is within the limit AND every required verdict of summary.json is true;
// the study file names the verdicts strictly.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "feeddrive/study/report.hpp"
#include "feeddrive/study/spec.hpp"
#include "study_util.hpp"

namespace feeddrive::study {
namespace {

using test::study_error;
using test::study_text;

Outcome outcome(double max_abs_m, double within_limits) {
  Outcome o;
  o.ok = true;
  o.metrics = {{"position_error_max_abs_m", max_abs_m}, {"control_signal_within_limits", within_limits}};
  return o;
}

TEST(StudyReportCriterion, RequireNamesVerdictsStrictly) {
  const Study s =
      parse_study(study_text("report: {limit: 0.8, require: [control_signal_within_limits]}\n"), ".", "s.yaml");
  ASSERT_EQ(s.report.require.size(), 1u);
  EXPECT_EQ(s.report.require[0], "control_signal_within_limits");
  EXPECT_TRUE(s.report.has_criterion());
  // A misspelt verdict: the nearest name.
  EXPECT_NE(
      study_error(study_text("report: {require: [control_signal_within_limit]}\n"))
          .find("report.require[0] = 'control_signal_within_limit': not a true/false verdict of summary.json (did you "
                "mean 'control_signal_within_limits'?)"),
      std::string::npos);
  // A number is a metric, not a verdict: nothing close, so the list of verdicts.
  const std::string e = study_error(study_text("report: {require: [position_error_max_abs_m]}\n"));
  EXPECT_NE(e.find("report.require[0] = 'position_error_max_abs_m': not a true/false verdict"), std::string::npos) << e;
  EXPECT_NE(e.find("control_signal_within_limits"), std::string::npos) << e;
  EXPECT_NE(study_error(study_text("report: {require: [control_chattering, control_chattering]}\n"))
                .find("report.require[1] = 'control_chattering': listed twice"),
            std::string::npos);
  EXPECT_NE(
      study_error(study_text("report: {require: {a: 1}}\n")).find("report.require = (a map): expected a list of names"),
      std::string::npos);
  EXPECT_FALSE(parse_study(study_text(""), ".", "s.yaml").report.has_criterion());
}

// Each way to fail, one at a time: over the limit, a verdict false, a verdict missing (an
// outcome of an older version), a failed case, no value; and the case that passes.
TEST(StudyReportCriterion, ACasePassesOnlyWithinTheLimitAndWithEveryVerdictTrue) {
  const Study s =
      parse_study(study_text("report: {limit: 0.8, require: [control_signal_within_limits]}\n"), ".", "s.yaml");
  EXPECT_TRUE(case_passes(s, outcome(0.5e-6, 1.0), 0.5));
  EXPECT_TRUE(case_passes(s, outcome(0.8e-6, 1.0), 0.8));   // at the limit: passes (<=)
  EXPECT_FALSE(case_passes(s, outcome(0.9e-6, 1.0), 0.9));  // over the limit
  EXPECT_FALSE(case_passes(s, outcome(0.5e-6, 0.0), 0.5));  // the signal outside its limits
  Outcome old = outcome(0.5e-6, 1.0);
  old.metrics.pop_back();
  EXPECT_FALSE(case_passes(s, old, 0.5));  // no verdict recorded: not a pass
  Outcome failed;
  EXPECT_FALSE(case_passes(s, failed, NAN));
  EXPECT_FALSE(case_passes(s, outcome(0.5e-6, 1.0), NAN));  // no value of the metric
  // Only a limit: the verdict does not count; only a verdict: the metric does not.
  const Study limit_only = parse_study(study_text("report: {limit: 0.8}\n"), ".", "s.yaml");
  EXPECT_TRUE(case_passes(limit_only, outcome(0.5e-6, 0.0), 0.5));
  const Study verdict_only =
      parse_study(study_text("report: {require: [control_signal_within_limits]}\n"), ".", "s.yaml");
  EXPECT_TRUE(case_passes(verdict_only, outcome(5e-6, 1.0), 5.0));
  EXPECT_FALSE(case_passes(verdict_only, outcome(0.1e-6, 0.0), 0.1));
}

// report.md counts the passing cases per controller and per family, and says which verdicts a
// failing case missed.
TEST(StudyReportCriterion, ReportCountsPassingCasesPerFamily) {
  const Study s = parse_study(study_text("families:\n  - {name: a}\n  - {name: b}\n"
                                         "report: {limit: 0.8, require: [control_signal_within_limits]}\n"),
                              ".", "s.yaml");
  ReportData d(s);
  const auto add = [&](std::size_t index, std::size_t family, double max_abs_m, double within) {
    CaseRecord c;
    c.spec.controller = 0;
    c.spec.family = family;
    c.outcome = outcome(max_abs_m, within);
    d.add(index, c);
  };
  add(0, 0, 0.5e-6, 1.0);  // passes
  add(1, 1, 0.5e-6, 0.0);  // signal outside the limits
  const std::string md = report_md(d, "cmd", "");
  EXPECT_NE(md.find("## Cases that pass per family"), std::string::npos) << md;
  EXPECT_NE(md.find("| a | 1 of 1 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| b | **0 of 1** (1 fail a verdict) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 1 of 2 |"), std::string::npos) << md;  // the per-controller column
  EXPECT_NE(md.find("at most 0.8 um and `control_signal_within_limits` is true"), std::string::npos) << md;
  // Without a criterion, no pass table.
  const Study plain = parse_study(study_text(""), ".", "s.yaml");
  ReportData p(plain);
  EXPECT_EQ(report_md(p, "cmd", "").find("pass per family"), std::string::npos);
}

// report.md always tabulates, per controller, the worst of each of the four control-signal
// figures and the cases within the signal limits, whatever the report's metric and criterion (a
// study without `require` must not read as an all-clear on the command). A case without the
// verdict (an outcome of an older version) is counted apart, never as within the limits.
TEST(StudyReportCriterion, ReportAlwaysTabulatesTheSignalFiguresPerController) {
  const Study s = parse_study(study_text("report: {limit: 0.8}\n"), ".", "s.yaml");
  ReportData d(s);
  const auto add = [&](std::size_t index, double step, double changes, double hf, double sat, double within) {
    CaseRecord c;
    c.spec.controller = 0;
    c.spec.family = 0;
    c.outcome = outcome(0.5e-6, within);
    c.outcome.metrics.push_back({"control_step_rms_V", step});
    c.outcome.metrics.push_back({"control_direction_changes_per_s", changes});
    c.outcome.metrics.push_back({"force_hf_rms_N", hf});
    c.outcome.metrics.push_back({"control_saturated_fraction", sat});
    d.add(index, c);
  };
  add(0, 0.1, 1500.0, 20.0, 0.0, 1.0);
  add(1, 0.15, 4022.0, 25.0, 0.002, 0.0);  // within 0.8 um, but the command breaks the limits
  add(2, 0.05, 900.0, 5.0, 0.0, 1.0);
  const std::string md = report_md(d, "cmd", "");
  EXPECT_NE(md.find("## Control signal per controller"), std::string::npos) << md;
  EXPECT_NE(md.find("| **2 of 3** | 0.15 | 4022 | 25 | 0.002 |"), std::string::npos) << md;
  // The same cases without the verdict on one: unknown, not within.
  ReportData e(s);
  CaseRecord c;
  c.outcome.ok = true;
  c.outcome.metrics = {{"position_error_max_abs_m", 0.5e-6}, {"control_step_rms_V", 0.1}};
  e.add(0, c);
  const std::string me = report_md(e, "cmd", "");
  EXPECT_NE(me.find("| **0 of 1** (1 without the verdict) | 0.1 | – (1 without a value) |"), std::string::npos) << me;
}

}  // namespace
}  // namespace feeddrive::study
