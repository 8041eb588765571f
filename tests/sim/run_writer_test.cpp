// sim::RunWriter on records a real drive delivers: no true state (hardware reports only its
// encoder, drive_state_t.truth.valid = 0), so the error and force curves are NaN throughout.
// Before, gnuplot refused the empty error plot ("x range is invalid") and the whole output,
// timeseries.csv included, was discarded with exit 1: a monitored hardware run lost its data.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "../support/scratch.hpp"
#include "feeddrive/sim/output.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/summary.hpp"

namespace feeddrive::sim {
namespace {
namespace fs = std::filesystem;

TEST(RunWriter, ARunWithoutTrueStateKeepsItsDataAndGetsItsPlots) {
  const fs::path out = test_support::make_scratch("run_writer") / "no_truth";
  Scenario s;
  s.name = "hardware";
  s.control_period = 1e-4;
  s.duration = 0.1;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  RunWriter w(out.string(), s, "test");
  for (long k = 0; k < 1000; ++k) {
    Record r;
    r.t = s.time_of(k);
    r.xd = 1e-3 * r.t;
    r.x = r.v = r.z = r.fg = r.i = nan;  // no true state
    r.f_thrust = r.f_friction = r.f_ripple = r.f_grinding = nan;
    r.x_measured = r.xd + 5e-8 * std::floor(k / 7.0);
    r.u = r.u_unsaturated = std::sin(1e-2 * k);
    w.add(r);
  }
  w.finish(w.summary(0.0, {}), true);
  EXPECT_EQ(w.plot_error(), "");
  ASSERT_TRUE(fs::exists(out / "timeseries.csv"));
  EXPECT_GT(fs::file_size(out / "timeseries.csv"), 1000u * 20u);  // 1000 rows of 20 columns
  for (const char* png : {"position.png", "velocity_error.png", "control.png", "forces.png"}) {
    ASSERT_TRUE(fs::exists(out / png)) << png;
    EXPECT_GT(fs::file_size(out / png), 1000u) << png;  // a drawn PNG, not an empty file
  }
  const auto j = nlohmann::json::parse(test_support::slurp(out / "summary.json"));
  EXPECT_EQ(j["steps"], 1000);
  EXPECT_TRUE(j["position_error_max_abs_m"].is_null() || j["position_error_max_abs_m"].is_number());
}

TEST(RunWriter, AFailingGnuplotLosesNoData) {
  // gnuplot missing (taken off PATH) stands for any gnuplot failure: the data go in place.
  const fs::path out = test_support::make_scratch("run_writer") / "no_gnuplot";
  Scenario s;
  s.control_period = 1e-4;
  s.duration = 0.01;
  const char* old = std::getenv("PATH");
  const std::string saved = old ? old : "";
  setenv("PATH", "/nonexistent", 1);
  {
    RunWriter w(out.string(), s, "test");
    for (long k = 0; k < 100; ++k) {
      Record r;
      r.t = s.time_of(k);
      w.add(r);
    }
    w.finish(w.summary(0.0, {}), true);
    EXPECT_NE(w.plot_error(), "");
  }
  setenv("PATH", saved.c_str(), 1);
  EXPECT_TRUE(fs::exists(out / "timeseries.csv"));
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  EXPECT_FALSE(fs::exists(out / "position.png"));
}

TEST(RunWriter, OutputEveryKeepsStepsByTheirNumberAcrossGaps) {
  // output.every: N keeps steps k = 0, N, 2N, ... A record with gaps (a log, an attached
  // monitor) once kept every N-th row written instead, so its rows drifted off the multiples.
  const fs::path out = test_support::make_scratch("run_writer") / "every";
  Scenario s;
  s.control_period = 1e-4;
  s.duration = 0.01;
  s.output.every = 7;
  RunWriter w(out.string(), s, "test");
  for (long k = 0; k < 100; ++k) {
    if (k >= 3 && k <= 10) continue;  // a gap: steps 3-10 lost
    Record r;
    r.t = s.time_of(k);
    w.add(r);
  }
  w.finish(w.summary(0.0, {}), false);
  std::istringstream csv(test_support::slurp(out / "timeseries.csv"));
  std::string line;
  std::getline(csv, line);  // header
  std::vector<long> kept;
  while (std::getline(csv, line)) kept.push_back(std::lround(std::stod(line.substr(0, line.find(','))) / 1e-4));
  EXPECT_EQ(kept, (std::vector<long>{0, 14, 21, 28, 35, 42, 49, 56, 63, 70, 77, 84, 91, 98}));
}

}  // namespace
}  // namespace feeddrive::sim
