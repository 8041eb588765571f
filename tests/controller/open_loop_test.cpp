// Open-loop force sources (Xie & Liang Sec. 4): analytic step/sine/ramp forces, u = F/(Ka*Kf),
// and the table source (kind csv) with its zero-order hold and row-naming errors.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>

#include "controller_util.hpp"
#include "feeddrive/controller/open_loop.hpp"

namespace feeddrive::controller {
namespace {

using test::kPi;

// Force values by hand. Tolerance 1e-12 N: rounding of a sin() of an O(10) argument times 12 N.
TEST(OpenLoop, StepSineRampForces) {
  OpenLoopParams p;
  p.offset = 1.5;
  p.start_time = 0.2;
  p.kind = OpenLoopKind::kStep;
  p.amplitude = 12.0;
  {
    OpenLoopSource s(p);
    EXPECT_EQ(s.force(0.0), 1.5);
    EXPECT_EQ(s.force(0.1999), 1.5);
    EXPECT_EQ(s.force(0.2), 13.5);  // the step is on at t = start_time
    EXPECT_EQ(s.force(7.0), 13.5);
  }
  p.kind = OpenLoopKind::kSine;
  p.frequency = 10.0;
  p.phase = 0.4;
  {
    OpenLoopSource s(p);
    EXPECT_EQ(s.force(0.1), 1.5);  // before start: only the offset
    for (double t : {0.2, 0.21, 0.2375, 0.9, 3.3})
      EXPECT_NEAR(s.force(t), 1.5 + 12.0 * std::sin(2 * kPi * 10.0 * (t - 0.2) + 0.4), 1e-12) << t;
  }
  p.kind = OpenLoopKind::kRamp;
  p.rate = 100.0;
  p.amplitude = 30.0;  // cap at |F - offset| <= 30 N
  {
    OpenLoopSource s(p);
    EXPECT_EQ(s.force(0.0), 1.5);
    EXPECT_NEAR(s.force(0.3), 1.5 + 100.0 * 0.1, 1e-12);
    EXPECT_NEAR(s.force(0.49), 1.5 + 29.0, 1e-12);
    EXPECT_EQ(s.force(0.6), 31.5);  // capped (the cap is reached 0.3 s after start)
    EXPECT_EQ(s.force(9.0), 31.5);
  }
  p.rate = -100.0;  // the cap is symmetric
  {
    OpenLoopSource s(p);
    EXPECT_NEAR(s.force(0.3), 1.5 - 10.0, 1e-12);
    EXPECT_EQ(s.force(9.0), 1.5 - 30.0);
  }
  p.rate = 100.0;
  p.amplitude = 0.0;  // no cap
  {
    OpenLoopSource s(p);
    EXPECT_NEAR(s.force(10.2), 1.5 + 1000.0, 1e-9);
  }
}

// u = F/(Ka*Kf) at the measurement's time, saturated to [u_min, u_max]; the reference is ignored.
TEST(OpenLoop, CommandIsForceOverThrustGain) {
  OpenLoopParams p;
  p.kind = OpenLoopKind::kSine;
  p.amplitude = 130.0;
  p.frequency = 1.0;
  p.thrust_gain = 260.0;
  OpenLoopSource s(p);
  for (double t : {0.0, 0.1, 0.25, 0.77}) {
    const plant::Measurement m{t, 0.5, 0.1};
    const Command c = s.update({99.0, 9.0, 9.0, 9.0}, m, nullptr);
    EXPECT_NEAR(c.u, 130.0 * std::sin(2 * kPi * t) / 260.0, 1e-14) << t;
    EXPECT_EQ(c.u, c.u_unsaturated);
    EXPECT_TRUE(std::isnan(c.sliding));
  }
  p.u_max = 0.3;
  p.u_min = -0.1;
  OpenLoopSource lim(p);
  const Command hi = lim.update({}, {0.25, 0.0, 0.0}, nullptr);  // F = 130 N: u = 0.5 V
  EXPECT_NEAR(hi.u_unsaturated, 0.5, 1e-15);
  EXPECT_EQ(hi.u, 0.3);
  EXPECT_EQ(lim.update({}, {0.75, 0.0, 0.0}, nullptr).u, -0.1);
  EXPECT_FALSE(s.needs_truth());
}

OpenLoopParams table_params(std::vector<double> t, std::vector<double> value, bool is_force) {
  OpenLoopParams p;
  p.kind = OpenLoopKind::kCsv;
  p.table_t = std::move(t);
  p.table_value = std::move(value);
  p.table_is_force = is_force;
  p.thrust_gain = 200.0;
  return p;
}

// Zero-order hold: the value of the last row with t_row <= t; 0 before the first row; the last
// value after the last row. (The table's CSV file is read by the scenario layer with
// feeddrive::csv: tests/output/csv_reader_test.cpp and tests/sim/scenario_test.cpp.)
TEST(OpenLoopTable, ForceZeroOrderHold) {
  OpenLoopSource s(table_params({0.1, 0.2, 0.35}, {10, -4.5, 130}, true));
  EXPECT_EQ(s.force(0.0), 0.0);
  EXPECT_EQ(s.force(0.0999), 0.0);
  EXPECT_EQ(s.force(0.1), 10.0);
  EXPECT_EQ(s.force(0.15), 10.0);
  EXPECT_EQ(s.force(0.2), -4.5);
  EXPECT_EQ(s.force(0.3499), -4.5);
  EXPECT_EQ(s.force(0.35), 130.0);
  EXPECT_EQ(s.force(100.0), 130.0);
  // u = F/(Ka*Kf); 130/200 and -4.5/200 to rounding.
  EXPECT_DOUBLE_EQ(s.update({}, {0.4, 0.0, 0.0}, nullptr).u, 0.65);
  EXPECT_DOUBLE_EQ(s.update({}, {0.25, 0.0, 0.0}, nullptr).u, -0.0225);
  EXPECT_EQ(s.update({}, {0.05, 0.0, 0.0}, nullptr).u, 0.0);
}

// A `u` table gives the command in volts directly; force() reports Ka*Kf*u.
TEST(OpenLoopTable, VoltageColumn) {
  OpenLoopSource s(table_params({0, 1.0}, {0.5, -0.25}, false));
  EXPECT_DOUBLE_EQ(s.update({}, {0.5, 0.0, 0.0}, nullptr).u, 0.5);
  EXPECT_DOUBLE_EQ(s.update({}, {1.5, 0.0, 0.0}, nullptr).u, -0.25);
  EXPECT_DOUBLE_EQ(s.force(0.5), 100.0);
}

// A bad table: one line naming the row and the value.
TEST(OpenLoopTable, BadTablesNameTheRow) {
  const auto message = [](const OpenLoopParams& p) {
    try {
      OpenLoopSource s(p);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message(table_params({}, {}, true)), "controller.file: kind = csv needs a table of at least one row");
  EXPECT_EQ(message(table_params({0, 1}, {1}, true)), "controller.file: the table has 2 times and 1 values");
  EXPECT_EQ(message(table_params({0, 0.5, 0.4}, {1, 2, 3}, true)),
            "controller.file[2].t = 0.4: must be greater than the previous t = 0.5");
  EXPECT_EQ(message(table_params({0, 1}, {1, std::nan("")}, false)),
            "controller.file[1].u = nan: must be a finite number");
}

TEST(OpenLoop, ValidateAndNames) {
  OpenLoopParams p;
  EXPECT_NO_THROW(p.validate());
  const auto expect_invalid = [](const OpenLoopParams& q, const std::string& message) {
    try {
      q.validate();
      ADD_FAILURE() << "accepted; expected " << message;
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()), message);
    }
  };
  p = {};
  p.frequency = -1.0;
  expect_invalid(p, "controller.frequency = -1: must be >= 0");
  p = {};
  p.amplitude = std::nan("");
  expect_invalid(p, "controller.amplitude = nan: must be a finite number");
  p = {};
  p.start_time = -0.5;
  expect_invalid(p, "controller.start_time = -0.5: must be >= 0");
  p = {};
  p.thrust_gain = 0.0;
  expect_invalid(p, "controller.thrust_gain = 0: must be > 0");
  p = {};
  p.u_min = 1.0;
  p.u_max = -1.0;
  expect_invalid(p, "controller.u_max = -1: must be > u_min");
  p = {};
  p.kind = OpenLoopKind::kCsv;
  expect_invalid(p, "controller.file: kind = csv needs a table of at least one row");

  for (OpenLoopKind k : {OpenLoopKind::kStep, OpenLoopKind::kSine, OpenLoopKind::kRamp, OpenLoopKind::kCsv})
    EXPECT_EQ(fields::enum_from_name<OpenLoopKind>(to_string(k)), k);
  EXPECT_THROW(fields::enum_from_name<OpenLoopKind>("square"), std::invalid_argument);
}

}  // namespace
}  // namespace feeddrive::controller
