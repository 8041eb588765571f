// Study files: strict loading with one-line errors naming the key and the value.
#include <gtest/gtest.h>

#include "feeddrive/study/spec.hpp"
#include "study_util.hpp"

namespace feeddrive::study {
namespace {

using test::study_error;
using test::study_text;

TEST(StudySpec, DefaultsOneControllerAndOneNominalCase) {
  const Study s = parse_study(study_text(""), ".", "s.yaml");
  ASSERT_EQ(s.controllers.size(), 1u);
  EXPECT_EQ(s.controllers[0].name, "base");
  ASSERT_EQ(s.families.size(), 1u);
  EXPECT_EQ(s.families[0].name, "nominal");
  EXPECT_EQ(s.total_cases(), 1);
  EXPECT_EQ(s.model, ModelRule::kNominal);
}

TEST(StudySpec, ControllerFromScenarioTakesItsBlockAndControlPeriod) {
  const Study s = parse_study(study_text("controllers:\n  - {name: sgn, scenario: " + test::scenarios() +
                                         "/smc_jerk_limited.yaml, set: {plant.mass: 100}}\n"),
                              ".", "s.yaml");
  ASSERT_EQ(s.controllers.size(), 1u);
  EXPECT_NE(s.controllers[0].block.find("sgn"), std::string::npos);
  ASSERT_EQ(s.controllers[0].block_set.size(), 1u);
  EXPECT_EQ(s.controllers[0].block_set[0].key, "control_period");
  EXPECT_EQ(s.controllers[0].block_set[0].value, "2e-5");
  ASSERT_EQ(s.controllers[0].set.size(), 1u);
  EXPECT_EQ(s.controllers[0].set[0].key, "plant.mass");
}

TEST(StudySpec, AMisspeltReportMetricIsRefusedWithTheNearestName) {
  // Before: the study ran and its report showed every case as failed.
  const std::string e = study_error(study_text("report: {metric: position_eror_max_abs_m}\n"));
  EXPECT_NE(e.find("report.metric = 'position_eror_max_abs_m': not a metric of summary.json (did you mean "
                   "'position_error_max_abs_m'?)"),
            std::string::npos)
      << e;
  EXPECT_NE(
      study_error(study_text("report: {metric: wall_time_s}\n")).find("report.metric = 'wall_time_s': not a metric"),
      std::string::npos);  // a wall-clock metric is not in results.csv
  EXPECT_NE(study_error(study_text("report: {metric: wobble}\n"))
                .find("; one of control_period_s, steps, sim_time_s, position_error_max_abs_m, "),
            std::string::npos);  // nothing close: the list
  EXPECT_NO_THROW(parse_study(study_text("report: {metric: control_total_variation}\n"), ".", "s.yaml"));
}

TEST(StudySpec, ASeedBeyondSixtyFourBitsIsRefusedNotClamped) {
  const std::string mc =
      "families:\n  - name: f\n    monte_carlo:\n      draws: 2\n      parameters:\n"
      "        - {key: plant.mass, distribution: uniform, low: 90, high: 110}\n      seed: ";
  EXPECT_NO_THROW(parse_study(study_text(mc + "18446744073709551615\n"), ".", "s.yaml"));
  const std::string e = study_error(study_text(mc + "18446744073709551616\n"));
  EXPECT_NE(e.find("seed = '18446744073709551616': out of range (0 to 18446744073709551615)"), std::string::npos) << e;
}

TEST(StudySpec, CaseCountIsGridTimesDrawsTimesControllers) {
  const Study s = parse_study(study_text(R"(
controllers:
  - {name: a, controller: {type: cascade}}
  - {name: b, controller: {type: cascade, kv: 900}}
  - {name: c, controller: {type: sliding_mode}}
families:
  - name: nominal
  - name: g
    grid:
      - {key: plant.mass, values: [90, 100, 110]}
      - {keys: [plant.friction.static_force, plant.friction.coulomb_force], scale: [0.7, 1.3]}
    monte_carlo:
      draws: 4
      seed: 3
      parameters:
        - {key: plant.friction.viscous, distribution: lognormal, mu: 0, sigma: 0.2, scale: true}
)"),
                              ".", "s.yaml");
  EXPECT_EQ(s.family_cases(0), 1);
  EXPECT_EQ(s.family_cases(1), 3 * 2 * 4);
  EXPECT_EQ(s.total_cases(), 3 * (1 + 24));
}

TEST(StudySpec, BadFilesGetOneLineErrorsNamingKeyAndValue) {
  const std::string fam = "families:\n  - name: f\n";
  EXPECT_NE(study_error(study_text("familes: []\n")).find("familes: unknown key (did you mean 'families'?)"),
            std::string::npos);
  EXPECT_NE(study_error(study_text(fam + "    grid: []\n")).find("families[0].grid: empty grid"), std::string::npos);
  EXPECT_NE(study_error(study_text(fam + "    grid:\n      - {key: plant.mass, values: []}\n")).find("empty grid axis"),
            std::string::npos);
  EXPECT_NE(study_error(study_text(fam + "    grid:\n      - {key: plant.mass, values: [.nan]}\n"))
                .find("families[0].grid[0].values[0] = '.nan': NaN is not allowed"),
            std::string::npos);
  EXPECT_NE(study_error(study_text(fam + "    grid:\n      - {key: plant.mass, scale: [x]}\n"))
                .find("families[0].grid[0].scale[0] = 'x': not a number"),
            std::string::npos);
  EXPECT_NE(study_error(study_text(fam + "    grid:\n      - {key: 'plant..mass', values: [1]}\n"))
                .find("not a dotted scenario key"),
            std::string::npos);
  EXPECT_NE(study_error(study_text(fam + "    grid:\n      - {keys: [a, b], values: [[1, 2, 3]]}\n"))
                .find("expected one value per key (2)"),
            std::string::npos);
  const std::string mc = fam + "    monte_carlo:\n";
  EXPECT_NE(
      study_error(
          study_text(
              mc +
              "      draws: 2\n      seed: 1\n      parameters:\n        - {key: plant.mass, distribution: cauchy}\n"))
          .find("distribution = 'cauchy': expected one of uniform, normal, lognormal"),
      std::string::npos);
  EXPECT_NE(study_error(study_text(mc + "      draws: 2\n      seed: 1\n      parameters:\n        - {key: plant.mass, "
                                        "distribution: uniform, low: 2, high: 1}\n"))
                .find("parameters[0].high = 1: must be > low (2)"),
            std::string::npos);
  EXPECT_NE(study_error(study_text(mc + "      draws: 2\n      seed: 1\n      parameters:\n        - {key: plant.mass, "
                                        "distribution: normal, mean: 1}\n"))
                .find("stddev: missing (required by distribution normal)"),
            std::string::npos);
  EXPECT_NE(study_error(study_text(mc + "      draws: 2\n      seed: 1\n      parameters:\n        - {key: plant.mass, "
                                        "distribution: normal, mean: 0, stddev: 1, low: 50, high: 60}\n"))
                .find("holds almost none of the distribution"),
            std::string::npos);
  EXPECT_NE(study_error(study_text(mc + "      draws: 2\n      parameters:\n        - {key: plant.mass, distribution: "
                                        "uniform, low: 1, high: 2}\n"))
                .find("seed: missing"),
            std::string::npos);
  EXPECT_NE(study_error(study_text(mc + "      draws: 0\n      seed: 1\n      parameters: []\n"))
                .find("draws = 0: must be >= 1"),
            std::string::npos);
  // Impossible case counts: each axis is fine, the product is not.
  std::string axis = "[";
  for (int i = 0; i < 100; ++i) axis += (i ? ",1" : "1");
  axis += "]";
  std::string huge = fam + "    grid:\n";
  for (int i = 0; i < 4; ++i) huge += "      - {key: plant.k" + std::to_string(i) + ", values: " + axis + "}\n";
  EXPECT_NE(study_error(study_text(huge)).find("more than 1000000 cases"), std::string::npos);
  EXPECT_NE(
      study_error(
          study_text(
              "controllers:\n  - {name: a, controller: {type: cascade}}\n  - {name: a, controller: {type: cascade}}\n"))
          .find("controllers[1].name = 'a': used twice"),
      std::string::npos);
  EXPECT_NE(study_error(study_text("controllers:\n  - {name: a}\n")).find("give exactly one of controller:"),
            std::string::npos);
  EXPECT_NE(study_error("name: t\n").find("base: missing"), std::string::npos);
  EXPECT_NE(study_error("name: t\nbase: /nonexistent.yaml\n").find("/nonexistent.yaml: cannot read the base file"),
            std::string::npos);
  EXPECT_NE(study_error("name: [t\n").find("YAML syntax error"), std::string::npos);
  EXPECT_NE(study_error(study_text("report: {scale: .nan}\n")).find("report.scale = '.nan': NaN is not allowed"),
            std::string::npos);
}

}  // namespace
}  // namespace feeddrive::study

namespace feeddrive::study {
namespace {
// Review of issue 23 (F17): a study file is not a scenario for --sweep, and one key swept twice
// would silently lose the first sweep's values.
TEST(StudySpec, SweepRefusesAStudyFileAndAKeySweptTwice) {
  const std::string scen = test::scenarios() + "/smc_bl_jerk_limited.yaml";
  const std::string study = std::string(FEEDDRIVE_SOURCE_DIR) + "/studies/robustness.yaml";
  try {
    sweep_study(study, {parse_sweep("plant.mass=1,2")});
    ADD_FAILURE() << "a study file was taken as a scenario";
  } catch (const StudyError& e) {
    EXPECT_NE(std::string(e.what()).find("--sweep takes a scenario file, not a study file (" + study + " has base/"),
              std::string::npos)
        << e.what();
  }
  const auto sweep_error = [&](const std::vector<std::string>& sweeps) {
    std::vector<GridAxis> axes;
    for (const std::string& w : sweeps) axes.push_back(parse_sweep(w));
    try {
      sweep_study(scen, axes);
    } catch (const StudyError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(sweep_error({"plant.mass=80,100", "plant.mass=1,2"}),
            "--sweep plant.mass and --sweep plant.mass: one key swept twice in family 'sweep' (give all its values in "
            "one --sweep)");
  // The old spelling of a key is that key (sim::canonical_key): two cases both with 3 before.
  EXPECT_EQ(
      sweep_error({"plant.effects.cogging_ripple.amplitude_N=1,2", "plant.effects.cogging_ripple.cogging_amplitude=3"}),
      "--sweep plant.effects.cogging_ripple.amplitude_N and --sweep "
      "plant.effects.cogging_ripple.cogging_amplitude (both plant.effects.cogging_ripple.cogging_amplitude): "
      "one key swept twice in family 'sweep' (give all its values in one --sweep)");
  // Different keys make a grid; a log sweep is marked for the report's log axis.
  const Study s =
      sweep_study(scen, {parse_sweep("plant.mass=80,100"), parse_sweep("plant.sensor.quantization=log:1e-9:1e-6:3")});
  EXPECT_EQ(s.total_cases(), 6);
  EXPECT_FALSE(s.families[0].grid[0].log);
  EXPECT_TRUE(s.families[0].grid[1].log);
}
}  // namespace
}  // namespace feeddrive::study

namespace feeddrive::study {
namespace {
// Review of issue 22 (item 2): within one family a key is varied once, whatever its spelling, in
// a study file as with --sweep: a key of two axes, or of an axis and a Monte Carlo parameter,
// once exited 0 with duplicate cases (the later axis' values only).
TEST(StudySpec, AKeyVariedTwiceInOneFamilyIsRefusedWhateverItsSpelling) {
  const std::string fam = "families:\n  - name: f\n";
  EXPECT_EQ(study_error(study_text(fam + "    grid: [{key: plant.mass, values: [100, 120]}, {key: plant.mass, "
                                         "values: [3]}]\n")),
            "s.yaml: families[0]: grid[0] plant.mass and grid[1] plant.mass: one key varied twice in family 'f' "
            "(give all its values in one axis or parameter)");
  EXPECT_EQ(study_error(study_text(fam + "    grid: [{keys: [plant.mass, plant.effects.cogging_ripple.amplitude_N], "
                                         "values: [[1, 2]]}]\n    monte_carlo: {draws: 2, seed: 1, parameters: "
                                         "[{key: plant.effects.cogging_ripple.cogging_amplitude, distribution: "
                                         "uniform, low: 1, high: 2}]}\n")),
            "s.yaml: families[0]: grid[0] plant.effects.cogging_ripple.amplitude_N and monte_carlo.parameters[0] "
            "plant.effects.cogging_ripple.cogging_amplitude (both plant.effects.cogging_ripple.cogging_amplitude): "
            "one key varied twice in family 'f' (give all its values in one axis or parameter)");
  EXPECT_NE(study_error(study_text("families:\n  - name: a\n  - name: g\n    grid: [{keys: "
                                   "[plant.effects.constant_force.force, plant.effects.constant_force.force_N], "
                                   "values: [[1, 2]]}]\n"))
                .find("families[1]: grid[0] plant.effects.constant_force.force and grid[0] "
                      "plant.effects.constant_force.force_N (both plant.effects.constant_force.force)"),
            std::string::npos);
  // One key in two families is two families' cases, not a mistake.
  const Study s = parse_study(study_text("families:\n  - {name: a, grid: [{key: plant.mass, values: [1, 2]}]}\n"
                                         "  - {name: b, grid: [{key: plant.mass, values: [3]}]}\n"),
                              ".", "s.yaml");
  EXPECT_EQ(s.total_cases(), 3);
}

// Review of issue 22 (item 2): the study's enums are read and written through their one table.
TEST(StudySpec, ModelAndDistributionAreEnumsOfOneTable) {
  EXPECT_EQ(parse_study(study_text("model: follows_plant\n"), ".", "s.yaml").model, ModelRule::kFollowsPlant);
  EXPECT_EQ(study_error(study_text("model: follow_plant\n")),
            "s.yaml: model = 'follow_plant': expected one of nominal, follows_plant");
  for (const auto& [d, name] : enum_names(Distribution{})) {
    EXPECT_EQ(fields::enum_from_name<Distribution>(name), d);
    EXPECT_STREQ(fields::enum_name(d), name);
  }
  EXPECT_EQ(fields::enum_choices<Distribution>(), "uniform, normal, lognormal");
}
}  // namespace
}  // namespace feeddrive::study
