// feeddrive-fit on real measured data: the EMPS estimation record (data/emps/README.md; Janot,
// Gautier & Brunot 2019), a ball-screw drive under closed-loop position control, 24.84 s at 1 kHz.
// The model knows only the mass (scenarios/fit/emps.yaml). The published inverse-dynamics model is
//     M x'' + Fv x' + Fc sign(x') + offset = motor force,
//     M = 95.1089 kg, Fv = 203.5 N s/m, Fc = 20.39 N, offset = -3.16 N.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numeric>
#include <set>

#include "feeddrive/fit/data.hpp"
#include "feeddrive/fit/sanity.hpp"
#include "feeddrive/fit/workflow.hpp"
#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::fit {
namespace {

// The record as the fit reads it (its columns by name).
MeasuredData emps_data() {
  CsvOptions csv;
  csv.time_column = "t_s";
  csv.position_column = "position_m";
  csv.force_column = "motor_force_N";
  csv.reference_column = "reference_m";
  return load_csv(FEEDDRIVE_SOURCE_DIR "/data/emps/emps_estimation.csv", csv);
}

// A real record passes the sanity checks before fitting (fit/sanity.hpp): its 50 nm steps, no
// sensor in the scenario (the record's own step is the quantum, noise unknown), a closed loop's
// thrust. Its strongest doublet in the second difference is 7.0 sensor steps and 1.8x its own
// scale, within the position-step check's 20 and 8.
TEST(Emps, PassesTheSanityChecks) {
  const MeasuredData data = emps_data();
  const sim::Scenario model = sim::load_scenario(FEEDDRIVE_SOURCE_DIR "/scenarios/fit/emps.yaml");
  EXPECT_NO_THROW(check_record(data, model.plant, model.control_period));
  EXPECT_NO_THROW(check_force_scale(prepare(data), model.plant));
}

TEST(Emps, NamesThePublishedModelAndNothingForeign) {
  const MeasuredData data = emps_data();
  const sim::Scenario model = sim::load_scenario(FEEDDRIVE_SOURCE_DIR "/scenarios/fit/emps.yaml");
  EXPECT_FALSE(model.grinding_process);
  FitOptions opt;
  const FitResult r =
      run_fit(prepare(data), model.plant, opt, [](const std::string& s) { std::printf("  %s\n", s.c_str()); });
  std::map<std::string, std::map<std::string, double>> found;
  for (const auto& e : r.effects) found[e.name] = e.parameters;
  // The tolerance: each within 10 % of the published value. The published values are a
  // least-squares fit with a relative force error of about 4 % (data/emps/README.md), and ours
  // differ from theirs in the residual (filtered, not differentiated) and in the Coulomb form
  // (tanh with a fitted transition velocity against sign).
  ASSERT_TRUE(found.count("viscous_friction")) << r.conclusion;
  ASSERT_TRUE(found.count("coulomb_friction")) << r.conclusion;
  ASSERT_TRUE(found.count("constant_force")) << r.conclusion;
  EXPECT_NEAR(found["viscous_friction"]["viscous"], 203.5, 0.10 * 203.5);
  EXPECT_NEAR(found["coulomb_friction"]["coulomb_force"], 20.39, 0.10 * 20.39);
  // The model's constant force opposes the thrust: the published offset on the force side is +F.
  EXPECT_NEAR(found["constant_force"]["force"], -3.16, 0.10 * 3.16);
  // Foreign to this drive: it does no grinding, has no spring, and its mass is the published one.
  for (const char* foreign : {"grinding_force", "spring_force", "mass_error"})
    EXPECT_FALSE(found.count(foreign)) << foreign;
  // Whatever else is named has its evidence: confirmed out of sample and by the replay.
  for (const StepResult& st : r.steps) {
    if (!st.accepted) continue;
    ASSERT_FALSE(st.cv_with.empty()) << st.effect.name;
    EXPECT_LT(std::accumulate(st.cv_with.begin(), st.cv_with.end(), 0.0),
              std::accumulate(st.cv_without.begin(), st.cv_without.end(), 0.0))
        << st.effect.name;
    EXPECT_LT(st.gap_after, st.gap_before) << st.effect.name;
  }
  // The three published terms take the replay gap from 147 um to under 10 um.
  EXPECT_LT(r.replay_final.gap, 10e-6);
  // Issue 20's point 7, "the EMPS record stays as it is": beyond the published model, the force
  // periodic in position of docs/fit.md (1.11 N at 78.5 mm, 3.1 periods over the travel), within
  // the 2 % pitch tolerance of the tests. A pitch search that started from a 2.48 mm alias lost it
  // (issue 20's third review) while every assertion above held.
  ASSERT_TRUE(found.count("cogging_ripple")) << r.conclusion;
  EXPECT_NEAR(found["cogging_ripple"]["pitch"], 0.0785, 0.02 * 0.0785);
  EXPECT_EQ(found.size(), 4u) << r.conclusion;
}

}  // namespace
}  // namespace feeddrive::fit
