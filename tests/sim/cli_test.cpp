// feeddrive-sim end to end: outputs, exit codes, and no half-written output folder.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace {
namespace fs = std::filesystem;

const std::string kSim = std::string(FEEDDRIVE_BINARY_DIR) + "/bin/feeddrive-sim";

// A scratch folder of this test process: ctest runs tests in parallel processes, which must not
// share file names.
fs::path scratch() {
  static const fs::path dir = [] {
    const fs::path d = fs::path(::testing::TempDir()) / ("feeddrive-cli-" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

struct ProcResult {
  int code;
  std::string err;
};

ProcResult run_sim(const std::string& args) {
  const fs::path err = scratch() / "sim_stderr.txt";
  const std::string cmd = kSim + " " + args + " --quiet 2> " + err.string();
  const int status = std::system(cmd.c_str());
  std::ifstream in(err);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
}

fs::path write_file(const std::string& name, const std::string& text) {
  const fs::path p = scratch() / name;
  std::ofstream(p) << text;
  return p;
}

const char* kGood = R"(
name: cli-check
duration: 0.05
control_period: 1e-4
plant: {friction: {model: lugre}, ripple: {enabled: true}, grinding: {enabled: true}}
controller: {type: sliding_mode, switching: sat, boundary_layer: 1e-3}
reference: {type: scurve, distance: 0.001, max_velocity: 0.02, max_acceleration: 1, max_jerk: 50}
)";

TEST(Cli, WritesTimeseriesSummaryAndPlots) {
  const fs::path scen = write_file("good.yaml", kGood);
  const fs::path out = scratch() / "cli_out";
  fs::remove_all(out);
  const ProcResult r = run_sim(scen.string() + " --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* f : {"timeseries.csv", "summary.json", "position.png", "velocity_error.png", "control.png", "forces.png"})
    EXPECT_TRUE(fs::exists(out / f)) << f;

  std::ifstream csv(out / "timeseries.csv");
  std::string header;
  std::getline(csv, header);
  for (const char* col : {"t", "xd", "vd", "ad", "x", "x_measured", "v", "z", "u", "f_friction", "f_ripple", "f_grinding"})
    EXPECT_NE(("," + header + ",").find(std::string(",") + col + ","), std::string::npos) << col;
  int rows = 0;
  for (std::string line; std::getline(csv, line);) ++rows;
  EXPECT_EQ(rows, 500);  // 0.05 s / 1e-4 s

  std::ifstream js(out / "summary.json");
  const auto j = nlohmann::json::parse(js);
  EXPECT_EQ(j["steps"].get<long>(), 500);
  EXPECT_NEAR(j["sim_time_s"].get<double>(), 0.05, 1e-12);
  for (const char* key : {"wall_time_s", "position_error_max_abs_m", "position_error_rms_m", "velocity_error_max_abs_mps",
                          "control_min", "control_max", "control_total_variation", "position_error_max_abs_settled_m"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_LE(j["control_min"].get<double>(), j["control_max"].get<double>());
}

void expect_bad_input(const std::string& scenario_text, const std::string& expected) {
  const fs::path scen = write_file("bad.yaml", scenario_text);
  const fs::path out = scratch() / "cli_bad_out";
  fs::remove_all(out);
  const ProcResult r = run_sim(scen.string() + " --out " + out.string());
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
  EXPECT_FALSE(fs::exists(out)) << "no output folder on bad input";
  for (const auto& e : fs::directory_iterator(scratch()))
    EXPECT_EQ(e.path().filename().string().find(".cli_bad_out.partial"), std::string::npos);
}

TEST(Cli, BadInputExitsTwoWithOneLine) {
  std::string s = kGood;
  expect_bad_input(std::string(kGood) + "plnt: {}\n", "plnt: unknown key (did you mean 'plant'?)");
  expect_bad_input(std::string(kGood).replace(s.find("plant: {"), 8, "plant: {mass: -1, "), "plant.mass = -1: must be > 0");
  expect_bad_input(std::string(kGood).replace(s.find("control_period: 1e-4"), 20, "control_period: 0"),
                   "control_period = 0: must be > 0");
  expect_bad_input(std::string(kGood).replace(s.find("plant: {"), 8, "plant: {mass: .nan, "), "plant.mass = '.nan'");
  expect_bad_input(std::string(kGood).replace(s.find("plant: {"), 8, "plant: {mass: , "), "plant.mass: missing value");
}

TEST(Cli, UnreadableScenarioAndMissingArguments) {
  const ProcResult r = run_sim("/nonexistent.yaml --out " + (scratch() / "x").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/nonexistent.yaml: cannot read the scenario file"), std::string::npos) << r.err;
  EXPECT_EQ(run_sim("").code, 2);
}

TEST(Cli, ExistingOutputIsReplacedWhole) {
  const fs::path scen = write_file("good2.yaml", kGood);
  const fs::path out = scratch() / "cli_replace";
  fs::create_directories(out);
  std::ofstream(out / "stale.txt") << "old";
  std::ofstream(out / "summary.json") << "{}";
  ASSERT_EQ(run_sim(scen.string() + " --out " + out.string() + " --no-plots").code, 0);
  EXPECT_FALSE(fs::exists(out / "stale.txt"));
  EXPECT_TRUE(fs::exists(out / "timeseries.csv"));
}

TEST(Cli, RefusesToReplaceAnUnrelatedFolder) {
  const fs::path scen = write_file("good3.yaml", kGood);
  const fs::path out = scratch() / "cli_precious";
  fs::create_directories(out);
  std::ofstream(out / "thesis.tex") << "keep me";
  const ProcResult r = run_sim(scen.string() + " --out " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("not a feeddrive output"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(out / "thesis.tex"));
}

}  // namespace
