// The fit's force cache (fit/model.cpp: force_residual keeps the filtered friction and grinding
// forces of the last model) is keyed by the params structs' one field list (fields::same): a
// field it left out made two models that differ only in that field share one residual. Found in
// review: the friction transition's shape (static_smoothing_shape) was missing from the
// hand-written comparison, so start_form's grid b = 0, 0.5, 1 scored all three as b = 0.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "feeddrive/common/fields.hpp"
#include "feeddrive/fit/model.hpp"
#include "feeddrive/plant/params.hpp"

namespace feeddrive::fit {
namespace {

// A 2 s sine of 5 mm at 1 Hz, sampled at 1 kHz, with a force input: reversals at every half
// period, where the static friction's transition shape acts.
MeasuredData sine_record() {
  MeasuredData d;
  d.source = "sine";
  d.input_kind = InputKind::kForce;
  for (int k = 0; k <= 2000; ++k) {
    const double t = 1e-3 * k;
    d.t.push_back(t);
    d.x.push_back(5e-3 * std::sin(2 * M_PI * t));
    d.input.push_back(20.0 * std::cos(2 * M_PI * t));
  }
  return d;
}

plant::PlantParams static_friction(double shape) {
  plant::PlantParams p;
  p.friction.model = plant::FrictionModel::kStatic;
  p.friction.static_smoothing_velocity = 5e-3;  // wide enough that the shape changes the force
  p.friction.static_smoothing_shape = shape;
  return p;
}

TEST(FieldsSame, EveryFieldOfTheListCountsNestedOnesIncluded) {
  plant::PlantParams a, b;
  EXPECT_TRUE(fields::same(a, b));
  b.friction.static_smoothing_shape = 0.5;
  EXPECT_FALSE(fields::same(a, b));
  EXPECT_FALSE(fields::same(a.friction, b.friction));
  b = a;
  b.grinding.enabled = !a.grinding.enabled;
  EXPECT_FALSE(fields::same(a, b));
}

TEST(ForceCache, AModelThatDiffersOnlyInTheTransitionShapeGetsItsOwnResidual) {
  const MeasuredData d = sine_record();
  const Record shared = prepare(d);
  const Eigen::VectorXd r0 = force_residual(shared, static_friction(0.0));
  const Eigen::VectorXd r1 = force_residual(shared, static_friction(1.0));  // same record: cache
  const Eigen::VectorXd fresh = force_residual(prepare(d), static_friction(1.0));
  ASSERT_EQ(r1.size(), fresh.size());
  // The cached and the fresh residual of one model are the same computation: equal to rounding.
  EXPECT_LT((r1 - fresh).cwiseAbs().maxCoeff(), 1e-9);
  // And the shape changes the force near each reversal (by newtons here), so the residuals of
  // shapes 0 and 1 must differ.
  EXPECT_GT((r0 - r1).cwiseAbs().maxCoeff(), 1e-3);
}

}  // namespace
}  // namespace feeddrive::fit
