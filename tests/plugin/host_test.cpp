// The controller plugin host (controller/plugin_host.hpp, docs/plugins.md): the example plugin
// (examples/plugin/smc_bl.c, built in-tree as a module) against the built-in sliding-mode law,
// record for record; and every way a plugin can fail, each one PluginError with one line that
// names the library and what failed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "feeddrive/common/validate.hpp"
#include "feeddrive/controller/plugin_host.hpp"
#include "feeddrive/plant/parameter_table.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/simulation.hpp"

namespace {

using namespace feeddrive;

std::string module(const std::string& name) { return std::string(FEEDDRIVE_PLUGIN_DIR) + "/lib" + name + ".so"; }

std::string error_of(const controller::PluginParams& p, int updates = 5) {
  try {
    controller::PluginController c(p);
    plant::Measurement m;
    for (int k = 0; k < updates; ++k) {
      m.t = k * 1e-3;
      c.update({}, m, nullptr);
    }
  } catch (const controller::PluginError& e) {
    return e.what();
  }
  return "";
}

controller::PluginParams params_of(const std::string& name) {
  controller::PluginParams p;
  p.library = module(name);
  return p;
}

void expect_one_line(const std::string& e, const std::string& library, const std::string& what) {
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  EXPECT_EQ(e.rfind("plugin " + library + ": ", 0), 0u) << e;
  EXPECT_NE(e.find(what), std::string::npos) << e;
}

TEST(PluginHost, ErrorsAreOneLineNamingLibraryAndCause) {
  expect_one_line(error_of(params_of("no_such_plugin")), module("no_such_plugin"), "no such file");
  expect_one_line(error_of(params_of("fd_fault_version")), module("fd_fault_version"),
                  "ABI version 999, this feeddrive hosts ABI version 2");
  // A plugin built for ABI version 1 (the struct of model fields): refused, both versions named.
  expect_one_line(error_of(params_of("fd_fault_old")), module("fd_fault_old"),
                  "ABI version 1, this feeddrive hosts ABI version 2 only (rebuild the plugin");
  expect_one_line(error_of(params_of("fd_fault_no_reset")), module("fd_fault_no_reset"),
                  "missing symbol feeddrive_controller_reset");
  expect_one_line(error_of(params_of("fd_fault_refuse")), module("fd_fault_refuse"),
                  "create refused: gain is required");
  expect_one_line(error_of(params_of("fd_fault_nan")), module("fd_fault_nan"),
                  "update at t = 0.002 s returned u = nan");
  expect_one_line(error_of(params_of("fd_fault_throw")), module("fd_fault_throw"),
                  "update at t = 0.001 s: an exception left the plugin");
  expect_one_line(error_of(params_of("fd_fault_fail")), module("fd_fault_fail"),
                  "update at t = 0.001 s failed: position sensor lost");
  auto p = params_of("fd_fault_none");
  p.parameters = {{"gian", "2"}};
  expect_one_line(error_of(p), module("fd_fault_none"), "create refused: unknown parameter 'gian'");
  // A file that is not a shared library.
  p.library = std::string(FEEDDRIVE_SOURCE_DIR) + "/README.md";
  expect_one_line(error_of(p), p.library, "cannot be loaded");
}

TEST(PluginHost, PassesParametersAndResetRestoresTheInitialState) {
  auto p = params_of("fd_fault_none");
  p.parameters = {{"gain", "2.5"}};
  controller::PluginController c(p);
  trajectory::Sample r;
  r.position = 1.0;
  plant::Measurement m;
  m.x = 0.2;
  controller::Command cmd;
  for (int k = 0; k < 3; ++k) cmd = c.update(r, m, nullptr);
  EXPECT_EQ(cmd.u, 2.5 * (1.0 - 0.2));      // the same expression, so exactly equal
  EXPECT_EQ(cmd.sliding, 3.0);              // three updates
  EXPECT_TRUE(std::isnan(cmd.z_estimate));  // a diagnostic the plugin did not set stays NaN
  c.reset();
  EXPECT_EQ(c.update(r, m, nullptr).sliding, 1.0);
}

TEST(PluginHost, ManyInstancesOfOneLibraryAreIndependent) {
  auto p = params_of("fd_fault_none");
  const auto lib = controller::PluginLibrary::open(p.library);
  controller::PluginController a(p, lib), b(p, lib);
  for (int k = 0; k < 4; ++k) a.update({}, {}, nullptr);
  EXPECT_EQ(a.update({}, {}, nullptr).sliding, 5.0);
  EXPECT_EQ(b.update({}, {}, nullptr).sliding, 1.0);
}

// The model a plugin is given is the plant's one list walked (plugin.h, feeddrive_run_info.model):
// every key of PlantParams' Serialize but the excluded sections, each with the model's value, read
// through plugin.h's own accessors; a field added to the list is there without further code (the
// struct of ABI version 1 was a hand copy that missed friction.static_smoothing_shape).
TEST(PluginRunInfo, ModelTableIsThePlantListWalked) {
  controller::PluginParams p;
  p.library = "unused.so";
  p.period = 2e-4;
  p.u_min = -7.0;
  p.u_max = 8.0;
  p.model.mass = 91.5;
  p.model.friction.model = plant::FrictionModel::kStatic;
  p.model.friction.stribeck_exponent = 1.3;
  p.model.friction.static_smoothing_shape = 0.25;
  p.model.ripple.enabled = true;
  p.model.sensor.velocity = plant::VelocityMeasurement::kDifference;
  const controller::PluginRunInfo run(p);
  const feeddrive_run_info& info = run.info();
  EXPECT_EQ(info.abi_version, 2u);
  EXPECT_EQ(info.size, sizeof(feeddrive_run_info));
  EXPECT_EQ(info.period, 2e-4);
  EXPECT_EQ(info.u_min, -7.0);
  EXPECT_EQ(info.u_max, 8.0);

  // Every value of the list, walked here independently of the host's table.
  const std::vector<std::string> excluded = plant::table_excluded_keys();
  std::size_t listed = 0;
  for (const fields::FlatValue& v : fields::flatten(p.model)) {
    const bool out = std::any_of(excluded.begin(), excluded.end(),
                                 [&](const std::string& e) { return v.key.rfind(e + ".", 0) == 0; });
    double number = -12345.0;
    if (out) {
      EXPECT_FALSE(feeddrive_model_number(&info, v.key.c_str(), &number)) << v.key << " should be left out";
      EXPECT_EQ(feeddrive_model_name(&info, v.key.c_str()), nullptr) << v.key;
      continue;
    }
    ++listed;
    if (v.is_name) {
      const char* name = feeddrive_model_name(&info, v.key.c_str());
      ASSERT_NE(name, nullptr) << v.key;
      EXPECT_EQ(std::string(name), v.name) << v.key;
      EXPECT_FALSE(feeddrive_model_number(&info, v.key.c_str(), &number)) << v.key << " is a name";
    } else {
      ASSERT_TRUE(feeddrive_model_number(&info, v.key.c_str(), &number)) << v.key;
      EXPECT_EQ(std::memcmp(&number, &v.number, sizeof number), 0) << v.key << " = " << number;  // bit for bit
    }
  }
  EXPECT_GT(listed, 40u);  // mass, Ka, Kf, the limit and the friction, ripple, grinding, ... sections
  EXPECT_EQ(info.model_size, listed + plant::table_derived_keys().size());

  // The values this test set, by their scenario keys, and the derived ones.
  double x = 0.0;
  ASSERT_TRUE(feeddrive_model_number(&info, "friction.static_smoothing_shape", &x));
  EXPECT_EQ(x, 0.25);
  ASSERT_TRUE(feeddrive_model_number(&info, "friction.stribeck_exponent", &x));
  EXPECT_EQ(x, 1.3);
  ASSERT_TRUE(feeddrive_model_number(&info, "mass", &x));
  EXPECT_EQ(x, 91.5);
  ASSERT_TRUE(feeddrive_model_number(&info, "ripple.enabled", &x));
  EXPECT_EQ(x, 1.0);  // a flag is 1 or 0
  EXPECT_STREQ(feeddrive_model_name(&info, "friction.model"), "static");
  EXPECT_STREQ(feeddrive_model_name(&info, "sensor.velocity"), "difference");
  ASSERT_TRUE(feeddrive_model_number(&info, "thrust_gain", &x));
  EXPECT_EQ(x, p.model.thrust_gain());
  ASSERT_TRUE(feeddrive_model_number(&info, "grinding.damping", &x));
  EXPECT_EQ(x, p.model.grinding.damping());
  EXPECT_FALSE(feeddrive_model_number(&info, "friction.stribeck_exponant", &x));  // a misspelt key: not found
  EXPECT_EQ(feeddrive_model_name(&info, "mass"), nullptr);                        // a number, not a name
}

// A derived value of the table is never a key of the list (it would shadow it).
TEST(PluginRunInfo, DerivedKeysAreNotKeysOfTheList) {
  for (const fields::FlatValue& v : fields::flatten(plant::PlantParams{}))
    for (const std::string& d : plant::table_derived_keys()) EXPECT_NE(v.key, d);
}

// The built-in boundary-layer law's scenario with the example plugin in its place: its model, its
// gains as the plugin's parameters.
sim::Scenario as_example_plugin(const sim::Scenario& builtin) {
  const controller::SlidingModeParams& smc = builtin.controller.sliding_mode;
  sim::Scenario plugin = builtin;
  sim::use_plugin(plugin, std::string(FEEDDRIVE_EXAMPLE_PLUGIN));
  plugin.controller.plugin.model = smc.model;
  plugin.controller.plugin.parameters = {{"eta", validate::format_number(smc.eta)},
                                         {"k", validate::format_number(smc.k)},
                                         {"lambda", validate::format_number(smc.lambda)},
                                         {"switching", "sat"},
                                         {"boundary_layer", validate::format_number(smc.boundary_layer)}};
  return plugin;
}

// Every record of the two runs the same, bit for bit.
void expect_same_records(const sim::Scenario& builtin, const sim::Scenario& plugin, const std::string& name) {
  const auto a = sim::run(builtin), b = sim::run(plugin);
  ASSERT_EQ(a.records.size(), b.records.size());
  for (std::size_t k = 0; k < a.records.size(); ++k) {
    const auto va = sim::record_values(a.records[k]), vb = sim::record_values(b.records[k]);
    ASSERT_EQ(std::memcmp(va.data(), vb.data(), va.size() * sizeof(double)), 0)
        << name << ": record " << k << " differs";
  }
}

// The example plugin (the boundary-layer law in C) against the built-in sliding_mode law on the
// paper's moves: every record identical, bit for bit (it computes the same terms in the same
// order). The ramp with friction, ripple and grinding exercises every force term it compensates.
TEST(PluginHost, ExamplePluginEqualsBuiltInLawRecordForRecord) {
  for (const char* name : {"smc_bl_jerk_limited", "smc_bl_ramp_all_forces"}) {
    sim::Scenario builtin =
        sim::load_scenario(std::string(FEEDDRIVE_SOURCE_DIR) + "/scenarios/paper/" + name + ".yaml");
    builtin.duration = 0.4;  // the move's start, its constant velocity and (ramp) the contact: 4,000 periods
    ASSERT_EQ(builtin.controller.type, sim::ControllerType::kSlidingMode);
    ASSERT_EQ(builtin.controller.sliding_mode.switching, controller::Switching::kSaturation);
    expect_same_records(builtin, as_example_plugin(builtin), name);
  }
}

// The same with the static friction law and a smoothed sign between tanh and the algebraic form
// (friction.static_smoothing_shape = 0.5): the plugin reads the shape from the host's table. With
// ABI version 1 it could not (the struct had no such field), and its tanh(v/eps) differed.
TEST(PluginHost, ExamplePluginEqualsBuiltInLawWithStaticFrictionShape) {
  sim::Scenario builtin =
      sim::load_scenario(std::string(FEEDDRIVE_SOURCE_DIR) + "/scenarios/paper/smc_bl_ramp_all_forces.yaml");
  builtin.duration = 0.2;
  for (plant::PlantParams* m : {&builtin.plant, &builtin.controller.sliding_mode.model}) {
    m->friction.model = plant::FrictionModel::kStatic;
    m->friction.static_smoothing_velocity = 1e-3;  // wide enough that the shape shows in the force
    m->friction.static_smoothing_shape = 0.5;
    m->friction.stribeck_exponent = 1.5;
  }
  expect_same_records(builtin, as_example_plugin(builtin), "static friction, shape 0.5");
}

}  // namespace

namespace {

std::string plugin_scenario(const std::string& controller_extra) {
  return "duration: 0.01\ncontrol_period: 1e-4\nplant: {friction: {model: lugre}}\n"
         "controller:\n  type: plugin\n  library: " +
         std::string(FEEDDRIVE_EXAMPLE_PLUGIN) + "\n" + controller_extra +
         "reference: {type: step, amplitude: 1.0e-6}\n";
}

std::string load_error(const std::string& yaml) {
  try {
    sim::parse_scenario(yaml);
  } catch (const sim::ScenarioError& e) {
    return e.what();
  }
  return "";
}

// The scenario keys: parameters as text (numbers in their shortest exact text), limits, the
// nominal model defaulting to the plant; bad keys refused with one line naming them.
TEST(PluginScenario, KeysAreReadAndBadOnesRefused) {
  const sim::Scenario s = sim::parse_scenario(
      plugin_scenario("  parameters: {eta: 5.0, lambda: 5.0e+1, boundary_layer: 0.0005, switching: sat}\n  u_max: 8\n"
                      "  model: {mass: 90}\n"));
  ASSERT_EQ(s.controller.type, sim::ControllerType::kPlugin);
  const std::vector<std::pair<std::string, std::string>> want = {
      {"eta", "5"}, {"lambda", "50"}, {"boundary_layer", "5e-04"}, {"switching", "sat"}};  // std::to_chars shortest
  EXPECT_EQ(s.controller.plugin.parameters, want);
  EXPECT_EQ(s.controller.plugin.u_max, 8.0);
  EXPECT_EQ(s.controller.plugin.u_min, -10.0);
  EXPECT_EQ(s.controller.plugin.model.mass, 90.0);
  EXPECT_EQ(s.controller.plugin.model.friction.model, plant::FrictionModel::kLuGre);  // from the plant
  EXPECT_EQ(s.controller.plugin.period, 1e-4);

  EXPECT_NE(load_error(plugin_scenario("  parameters: {bad-name: 1}\n")).find("controller.parameters.bad-name"),
            std::string::npos);
  EXPECT_NE(load_error(plugin_scenario("  parameters: {eta: .nan}\n")).find("controller.parameters.eta"),
            std::string::npos);
  EXPECT_NE(load_error(plugin_scenario("  parameters: {eta: [1, 2]}\n")).find("controller.parameters.eta"),
            std::string::npos);
  EXPECT_NE(load_error(plugin_scenario("  libary: x.so\n")).find("libary"), std::string::npos);
  EXPECT_NE(load_error(plugin_scenario("  model: {effects: {constant_force: {force: 1}}}\n"))
                .find("controller.model.effects"),
            std::string::npos);
  const std::string missing = load_error("duration: 0.01\ncontrol_period: 1e-4\ncontroller: {type: plugin}\n");
  EXPECT_NE(missing.find("controller.library"), std::string::npos) << missing;
  const std::string absent =
      load_error("duration: 0.01\ncontrol_period: 1e-4\ncontroller: {type: plugin, library: nowhere.so}\n");
  EXPECT_NE(absent.find("nowhere.so: no such file"), std::string::npos) << absent;
  EXPECT_EQ(absent.find('\n'), std::string::npos);
}

// A study keys and reloads its cases through the resolved keys: a plugin scenario round-trips
// (library, parameters as numbers or words, the model), and a study can vary a parameter.
TEST(PluginScenario, ResolvedKeysRoundTrip) {
  sim::ResolvedKeys first;
  sim::parse_scenario(plugin_scenario("  parameters: {eta: 5.0, switching: sat}\n"), ".", "scenario", &first);
  EXPECT_EQ(first.at("controller.parameters.eta").text, "5");
  EXPECT_FALSE(first.at("controller.parameters.eta").is_string);
  EXPECT_TRUE(first.at("controller.parameters.switching").is_string);
  EXPECT_EQ(first.at("controller.library").text, std::string(FEEDDRIVE_EXAMPLE_PLUGIN));
  EXPECT_TRUE(first.count("controller.model.mass"));
  const std::string yaml = sim::resolved_yaml(first);
  sim::ResolvedKeys second;
  const sim::Scenario s = sim::parse_scenario(yaml, ".", "resolved", &second);
  EXPECT_EQ(first, second);
  EXPECT_EQ(s.controller.plugin.parameters.size(), 2u);
}

}  // namespace
