// Strict scenario loading: every bad input is one line naming the key and the value.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/yaml_reader.hpp"
#include "scenario_error.hpp"

namespace feeddrive::sim {
namespace {

const char* kMinimal = R"(
duration: 0.01
control_period: 1e-4
plant: {}
controller: {type: sliding_mode}
reference: {type: sine, amplitude: 0.1, frequency: 1.0}
)";

using test::error_of;

std::string with(const std::string& from, const std::string& to) {
  std::string s = kMinimal;
  const auto pos = s.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return s.replace(pos, from.size(), to);
}

// Issue 23, review: a section that is off still has its written keys checked (exit 2), and the
// loader warns that they do not act (a forgotten `enabled: true`).
TEST(Scenario, ASectionThatIsOffIsCheckedAndWarnedAbout) {
  EXPECT_EQ(error_of(with("plant: {}", "plant: {ripple: {pitch: -1}}")),
            "s.yaml: plant.ripple.pitch = -1: must be > 0");
  EXPECT_EQ(error_of(with("plant: {}", "plant: {grinding: {workpiece_diameter: -1}}")),
            "s.yaml: plant.grinding.workpiece_diameter = -1: must be > 0");
  const Scenario s = parse_scenario(with("plant: {}", "plant: {ripple: {cogging_amplitude: 6, pitch: 0.03}}"));
  EXPECT_FALSE(s.plant.ripple.enabled);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0],
            "plant.ripple: keys given, but the section is off (no enabled: true): they do not act; enabled: true?");
  // `enabled: false` written is off on purpose (the paper's scenarios keep their values so): no warning.
  EXPECT_TRUE(parse_scenario(with("plant: {}", "plant: {ripple: {enabled: false, pitch: 0.03}}")).warnings.empty());
}

// A step after the end of the run is a move the run cuts off (was: null, and a perfect-looking
// max |e| = 0), with the likely unit named.
TEST(Scenario, AStepAfterTheRunIsAMoveCutOff) {
  const Scenario s = parse_scenario(with("reference: {type: sine, amplitude: 0.1, frequency: 1.0}",
                                         "reference: {type: step, amplitude: 1e-5, step_time: 500}"));
  EXPECT_EQ(s.move_end_s, 500.0);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("the run cuts it off (summary.json move_finished: false); a step_time in ms?"),
            std::string::npos)
      << s.warnings[0];
  const Scenario in_time = parse_scenario(with("reference: {type: sine, amplitude: 0.1, frequency: 1.0}",
                                               "reference: {type: step, amplitude: 1e-5, step_time: 0.005}"));
  EXPECT_TRUE(in_time.warnings.empty());
}

// --set with a list or a map in YAML's flow style reads it as the file would; a part set on
// `ripple: paper` keeps the preset (issue 23 review). The settings go into the struct as read.
TEST(Scenario, SetKeyTakesFlowListsAndMapsAndPartsOfAPreset) {
  Scenario s = read_scenario(kMinimal);
  set_read_keys(s, {{"output.columns", "[t, x, u]"},
                    {"plant.friction", "{model: none}"},
                    {"plant.ripple", "paper"},
                    {"plant.ripple.cogging_amplitude", "6"}});
  complete_read(s);
  EXPECT_EQ(s.output.columns, (std::vector<std::string>{"t", "x", "u"}));
  EXPECT_EQ(s.plant.friction.model, plant::FrictionModel::kNone);
  EXPECT_EQ(s.controller.sliding_mode.model.friction.model, plant::FrictionModel::kNone);  // the model follows
  EXPECT_TRUE(s.plant.ripple.enabled);
  EXPECT_EQ(s.plant.ripple.cogging_amplitude, 6.0);
  EXPECT_NE(s.plant.ripple.reluctance_amplitude, 0.0);  // the paper's other parts kept
  Scenario bad = read_scenario(kMinimal);
  EXPECT_THROW(set_read_key(bad, "output.columns", "[t, x"), ScenarioError);
}

// A section written without `enabled` is off: the warning comes from the presence facts the
// reader records (given_keys), so a section given by a setting warns the same.
TEST(Scenario, TheOffSectionWarningComesFromThePresenceFacts) {
  Scenario s = read_scenario(kMinimal);
  EXPECT_EQ(s.given_keys.count("plant.ripple"), 0u);
  set_read_key(s, "plant.grinding.stiffness", "2e6");
  complete_read(s);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0],
            "plant.grinding: keys given, but the section is off (no enabled: true): they do not act; enabled: true?");
  EXPECT_TRUE(s.grinding_process);
  Scenario on = read_scenario(kMinimal);
  set_read_keys(on, {{"plant.grinding.stiffness", "2e6"}, {"plant.grinding.enabled", "false"}});
  complete_read(on);
  EXPECT_TRUE(on.warnings.empty());
  // The short form of a preset says what it is: no warning.
  EXPECT_TRUE(parse_scenario(with("plant: {}", "plant: {ripple: none}")).warnings.empty());
}

TEST(Scenario, MinimalUsesDefaultsAndModelEqualsPlant) {
  const Scenario s = parse_scenario(kMinimal);
  EXPECT_EQ(s.steps(), 100);
  EXPECT_DOUBLE_EQ(s.plant.mass, 102.04);
  EXPECT_DOUBLE_EQ(s.plant.friction.bristle_stiffness, 2e6);
  EXPECT_EQ(s.controller.type, ControllerType::kSlidingMode);
  EXPECT_DOUBLE_EQ(s.controller.sliding_mode.model.mass, s.plant.mass);
  EXPECT_DOUBLE_EQ(s.controller.sliding_mode.period, 1e-4);
  EXPECT_DOUBLE_EQ(s.controller.sliding_mode.eta, 5.0);
}

TEST(Scenario, ControllerModelOverridesOnlyGivenKeys) {
  const Scenario s = parse_scenario(
      with("{type: sliding_mode}", "{type: sliding_mode, model: {mass: 110, friction: {coulomb_force: 70}}}"));
  EXPECT_DOUBLE_EQ(s.controller.sliding_mode.model.mass, 110.0);
  EXPECT_DOUBLE_EQ(s.controller.sliding_mode.model.friction.coulomb_force, 70.0);
  EXPECT_DOUBLE_EQ(s.controller.sliding_mode.model.friction.static_force, 120.0);
  EXPECT_DOUBLE_EQ(s.plant.mass, 102.04);
}

TEST(Scenario, UnknownKeySuggestsTheNearestKnownKey) {
  EXPECT_EQ(error_of(with("plant: {}", "plant: {frction: {model: none}}")),
            "s.yaml: plant.frction: unknown key (did you mean 'friction'?)");
  EXPECT_EQ(error_of(with("plant: {}", "plant: {friction: {coulomb: 3}}")),
            "s.yaml: plant.friction.coulomb: unknown key");
  EXPECT_EQ(error_of(std::string(kMinimal) + "durration: 3\n"),
            "s.yaml: durration: unknown key (did you mean 'duration'?)");
}

TEST(Scenario, MissingValuesAndSections) {
  EXPECT_EQ(error_of(with("plant: {}", "plant: {mass: }")), "s.yaml: plant.mass: missing value");
  EXPECT_EQ(error_of(with("duration: 0.01\n", "")), "s.yaml: duration: missing (required)");
  EXPECT_EQ(error_of(with("controller: {type: sliding_mode}", "controller: {eta: 3}")),
            "s.yaml: controller.type: missing (required)");
}

TEST(Scenario, NonPositiveMassAndPeriod) {
  EXPECT_EQ(error_of(with("plant: {}", "plant: {mass: 0}")), "s.yaml: plant.mass = 0: must be > 0");
  EXPECT_EQ(error_of(with("plant: {}", "plant: {mass: -3.5}")), "s.yaml: plant.mass = -3.5: must be > 0");
  EXPECT_EQ(error_of(with("control_period: 1e-4", "control_period: 0")), "s.yaml: control_period = 0: must be > 0");
  EXPECT_EQ(error_of(with("control_period: 1e-4", "control_period: -1e-4")),
            "s.yaml: control_period = -1e-04: must be > 0");  // the shortest text of the value (to_chars)
}

TEST(Scenario, NanInfAndGarbage) {
  EXPECT_EQ(error_of(with("plant: {}", "plant: {mass: .nan}")), "s.yaml: plant.mass = '.nan': NaN is not allowed");
  EXPECT_EQ(error_of(with("plant: {}", "plant: {mass: nan}")), "s.yaml: plant.mass = 'nan': NaN is not allowed");
  EXPECT_EQ(error_of(with("plant: {}", "plant: {mass: .inf}")), "s.yaml: plant.mass = .inf: must be finite");
  EXPECT_EQ(error_of(with("plant: {}", "plant: {mass: heavy}")), "s.yaml: plant.mass = 'heavy': not a number");
  EXPECT_EQ(error_of(with("plant: {}", "plant: {ripple: {enabled: maybe}}")),
            "s.yaml: plant.ripple.enabled = 'maybe': expected true or false");
  EXPECT_EQ(error_of(with("plant: {}", "plant: {mass: [1, 2]}")),
            "s.yaml: plant.mass = (a list): expected a single value");
}

TEST(Scenario, BadEnumsNameTheChoices) {
  EXPECT_NE(error_of(with("controller: {type: sliding_mode}", "controller: {type: pid}"))
                .find("controller.type = 'pid': expected one of sliding_mode, cascade, open_loop"),
            std::string::npos);
  EXPECT_NE(error_of(with("plant: {}", "plant: {friction: {model: dahl}}")).find("plant.friction.model = 'dahl'"),
            std::string::npos);
  EXPECT_NE(error_of(with("{type: sine, amplitude: 0.1, frequency: 1.0}", "{type: spline}"))
                .find("reference.type = 'spline'"),
            std::string::npos);
}

TEST(Scenario, ComponentValidationIsReported) {
  EXPECT_EQ(error_of(with("plant: {}", "plant: {friction: {static_force: 50}}")),
            "s.yaml: plant.friction.static_force = 50: must be >= coulomb_force");
  const std::string e = error_of(with("{type: sliding_mode}", "{type: sliding_mode, lambda: -1}"));
  EXPECT_NE(e.find("controller.lambda"), std::string::npos) << e;
  EXPECT_NE(e.find("-1"), std::string::npos) << e;
}

TEST(Scenario, SyntaxErrorNamesTheLine) {
  const std::string e = error_of("duration: 1\ncontrol_period: [1e-4\nplant: {}\n");
  EXPECT_NE(e.find("s.yaml: line"), std::string::npos) << e;
  EXPECT_NE(e.find("YAML syntax error"), std::string::npos) << e;
}

TEST(Scenario, UnreadableFile) {
  try {
    load_scenario("/nonexistent/feeddrive.yaml");
    FAIL();
  } catch (const ScenarioError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/feeddrive.yaml: cannot read the scenario file (No such file or directory)");
  }
}

TEST(Scenario, EveryShippedScenarioLoads) {
  for (const char* dir : {"/scenarios/paper", "/scenarios"}) {
    const std::string path = std::string(FEEDDRIVE_SOURCE_DIR) + dir;
    int n = 0;
    for (const auto& entry : std::filesystem::directory_iterator(path)) {
      if (entry.path().extension() != ".yaml") continue;
      EXPECT_NO_THROW(load_scenario(entry.path().string())) << entry.path();
      ++n;
    }
    if (std::string(dir) == "/scenarios/paper") {
      EXPECT_GE(n, 20);
    }
  }
}

// The scenario layer reads the tables a scenario names with the one CSV reader, when the
// scenario is loaded: the controller and trajectory libraries get data, and a bad file is a
// ScenarioError (exit 2) naming file:line:column and the value.
std::string temp_csv(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "feeddrive_scen_" + std::to_string(::getpid()) + "_" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

TEST(Scenario, TablesAreReadWhenTheScenarioIsLoaded) {
  const std::string force = temp_csv("force.csv", "\xEF\xBB\xBF# force\nt,note,force_N\r\n0.1,a,10\n0.2,b,-4.5\n");
  const Scenario ol = parse_scenario(
      with("controller: {type: sliding_mode}", "controller: {type: open_loop, kind: csv, file: '" + force + "'}"));
  EXPECT_EQ(ol.controller.open_loop.table_t, (std::vector<double>{0.1, 0.2}));
  EXPECT_EQ(ol.controller.open_loop.table_value, (std::vector<double>{10.0, -4.5}));
  EXPECT_TRUE(ol.controller.open_loop.table_is_force);
  EXPECT_DOUBLE_EQ(make_controller(ol)->update({}, {0.15, 0, 0}, nullptr).u_unsaturated, 10.0 / ol.plant.thrust_gain());

  const std::string wp = temp_csv("wp.csv", "t,x\n0,0\n0.5,0.01\n1,0.02\n");
  const Scenario w = parse_scenario(with("reference: {type: sine, amplitude: 0.1, frequency: 1.0}",
                                         "reference: {type: waypoints, file: '" + wp + "'}"));
  ASSERT_EQ(w.reference.waypoints.size(), 3u);
  EXPECT_DOUBLE_EQ(make_reference(w)->sample(0.5).position, 0.01);
}

TEST(Scenario, BadTablesAreOneLineScenarioErrors) {
  const std::string bad = temp_csv("bad.csv", "t,u\n0,1\n0.5,2x\n");
  EXPECT_EQ(error_of(with("controller: {type: sliding_mode}",
                          "controller: {type: open_loop, kind: csv, file: '" + bad + "'}")),
            "s.yaml: " + bad + ":3:5: column 'u': not a number: '2x'");
  EXPECT_EQ(error_of(with("controller: {type: sliding_mode}", "controller: {type: open_loop, kind: csv}")),
            "s.yaml: controller.file = '': kind = csv needs a file");
  EXPECT_EQ(error_of(with("reference: {type: sine, amplitude: 0.1, frequency: 1.0}",
                          "reference: {type: waypoints, file: /dev/zero}")),
            "s.yaml: /dev/zero: is a device, not a regular file");  // refused before it is opened for reading
}

TEST(Scenario, OutputOptions) {
  const Scenario s = parse_scenario(std::string(kMinimal) + "output: {every: 10, columns: [t, x, u]}\n");
  EXPECT_EQ(s.output.every, 10);
  EXPECT_EQ(s.output.columns, (std::vector<std::string>{"t", "x", "u"}));
  EXPECT_EQ(error_of(std::string(kMinimal) + "output: {columns: [t, t]}\n"),
            "s.yaml: output.columns: column 't' listed twice");
  EXPECT_EQ(error_of(std::string(kMinimal) + "output: {columns: []}\n"),
            "s.yaml: output.columns: empty list (leave the key out to record every column)");
  EXPECT_EQ(error_of(std::string(kMinimal) + "output: {every: 1.5}\n"), "s.yaml: output.every = '1.5': not an integer");
}

}  // namespace
}  // namespace feeddrive::sim
