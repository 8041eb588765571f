// Issue 10 point 7, closing the loop with the fit, end to end with the real tools: record the
// "real" drive (scenarios/fit/truth_cogging.yaml: a 15 N constant force and a 24 mm, 4 N cogging
// ripple the model lacks) with feeddrive-sim, fit it with feeddrive-fit from the nominal model
// (scenarios/fit/model.yaml), then run the sliding-mode controller of scenarios/fit/closed_loop.yaml
// on that same drive with the nominal model (before) and with the fitted model.fitted.yaml as
// controller.model (after). The fitted model must cut the tracking error.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/simulation.hpp"

namespace {
namespace fs = std::filesystem;

const std::string kBin = std::string(FEEDDRIVE_BINARY_DIR) + "/bin/";
const fs::path kScenarios = fs::path(FEEDDRIVE_SOURCE_DIR) / "scenarios" / "fit";

int run(const std::string& cmd) {
  const int status = std::system(("timeout 600 " + cmd + " > /dev/null").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

double max_abs_error(const feeddrive::sim::Scenario& s) {
  const feeddrive::sim::RunResult r = feeddrive::sim::run(s);
  double e = 0.0;
  for (const auto& rec : r.records) e = std::max(e, std::abs(rec.xd - rec.x));
  return e;
}

TEST(FitClosedLoop, TheFittedModelCutsTheTrackingErrorOnTheDriveItCameFrom) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("feeddrive-fit-loop-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  // 1. The measurement: 10 s of the real drive under its 1 kHz cascade (50 nm encoder, 20 nm noise).
  ASSERT_EQ(run(kBin + "feeddrive-sim " + (kScenarios / "truth_cogging.yaml").string() + " --out " +
                (dir / "truth").string() + " --no-plots"),
            0);
  // 2. The fit, from the nominal model, on the measured (quantized, noisy) position.
  ASSERT_EQ(run(kBin + "feeddrive-fit --scenario " + (kScenarios / "model.yaml").string() + " --data " +
                (dir / "truth" / "timeseries.csv").string() + " --position-column x_measured --no-plots -q --out " +
                (dir / "fit").string()),
            0);
  const feeddrive::sim::Scenario fitted = feeddrive::sim::load_scenario((dir / "fit" / "model.fitted.yaml").string());
  ASSERT_TRUE(fitted.plant.effects.constant_force.enabled);
  ASSERT_TRUE(fitted.plant.effects.cogging_ripple.enabled);

  // 3. The controller on the same drive: nominal model, then the fitted one (its effects and all).
  feeddrive::sim::Scenario loop = feeddrive::sim::load_scenario((kScenarios / "closed_loop.yaml").string());
  ASSERT_FALSE(loop.controller.sliding_mode.model.effects.any()) << "before: the nominal model";
  const double before = max_abs_error(loop);
  loop.controller.sliding_mode.model = fitted.plant;
  const double after = max_abs_error(loop);
  // Measured 3.18 um before and 0.055 um after (docs/fit.md). Before: the 19 N the model lacks,
  // absorbed only by the 200 rad/s disturbance state (dF/(m*w_o^2) ~ 4.7 um, the bound of
  // docs/controllers.md). After: what remains is the fit's error (0.004 N in force, 0.5e-3 in the
  // pitch) and the 50 nm encoder, which the nominal plant without effects also shows (0.064 um).
  // Required: at least 10x smaller, and within the paper's 0.8 um claim.
  EXPECT_GT(before, 1e-6) << "the hidden effects must matter, or the test shows nothing";
  EXPECT_LT(after, before / 10.0) << "before " << before * 1e6 << " um, after " << after * 1e6 << " um";
  EXPECT_LT(after, 0.8e-6);
  fs::remove_all(dir);
}

// The loop scenario's own record fitted with that same scenario (issue 20's review): 1.5 s at
// 10 kHz under the sliding-mode controller, ending at rest at 100 mm against the model's own 15 N
// constant force. The model is exact, so the verdict is "no discrepancy". It was "unexplained" at
// a gap of 1.73 um (70x the floor), all of it in the 0.3 s at rest: each replay window started
// with the bristle deflection integrated along the smoothed measured motion, which left the static
// friction out of balance and made the model creep (fit/src/replay.cpp, bristle_at_rest). The
// conclusion also called the model's own 15 N a "friction direction asymmetry" the fit had added.
// Tolerance: the gap of an exact model ends within 1.2-2.0x its floor (fit/verdict.hpp); 1.36x here.
TEST(FitClosedLoop, TheLoopScenariosOwnRecordShowsNoDiscrepancy) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("feeddrive-fit-own-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scenario = (kScenarios / "closed_loop.yaml").string();
  ASSERT_EQ(run(kBin + "feeddrive-sim " + scenario + " --out " + (dir / "sim").string() + " --no-plots"), 0);
  ASSERT_EQ(run(kBin + "feeddrive-fit --scenario " + scenario + " --data " + (dir / "sim" / "timeseries.csv").string() +
                " --position-column x_measured --no-plots -q --out " + (dir / "fit").string()),
            0);
  std::ifstream in(dir / "fit" / "findings.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["verdict"], "no_discrepancy") << j["conclusion"];
  EXPECT_LT(j["gap_final"].get<double>(), 2.0 * j["noise_floor"]["gap_m"].get<double>()) << j["conclusion"];
  EXPECT_TRUE(j["effects"].empty()) << j["conclusion"];
  EXPECT_EQ(j["model_form"]["direction_asymmetry_N"].get<double>(), 0.0) << j["conclusion"];
  EXPECT_EQ(j["conclusion"].get<std::string>().find("asymmetry"), std::string::npos) << j["conclusion"];
  const feeddrive::sim::Scenario fitted = feeddrive::sim::load_scenario((dir / "fit" / "model.fitted.yaml").string());
  EXPECT_DOUBLE_EQ(fitted.plant.effects.constant_force.force, 15.0);  // the model's own, kept as given
  fs::remove_all(dir);
}

}  // namespace
