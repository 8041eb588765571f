// Open-loop force sources (Xie & Liang Sec. 4): analytic step/sine/ramp forces, u = F/(Ka*Kf),
// and the CSV source with its zero-order hold and FILE:LINE error messages.
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

std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "feeddrive_open_loop_" + name;
  std::ofstream out(path);
  out << text;
  return path;
}

OpenLoopParams csv_params(const std::string& path) {
  OpenLoopParams p;
  p.kind = OpenLoopKind::kCsv;
  p.file = path;
  p.thrust_gain = 200.0;
  return p;
}

// Zero-order hold: the value of the last row with t_row <= t; 0 before the first row; the last
// value after the last row. Comments (#) and blank lines are skipped, CRLF is accepted, and
// other columns are ignored.
TEST(OpenLoopCsv, ForceColumnZeroOrderHold) {
  const std::string path = write_file("force.csv",
                                      "# applied force\n"
                                      "t,note,force_N\r\n"
                                      "0.1,a,10\r\n"
                                      "\n"
                                      "0.2,b,-4.5\n"
                                      "0.35,c,130\n");
  OpenLoopSource s(csv_params(path));
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

// A `u` column gives the command in volts directly; force() reports Ka*Kf*u.
TEST(OpenLoopCsv, VoltageColumn) {
  const std::string path = write_file("u.csv", "t,u\n0,0.5\n1.0,-0.25\n");
  OpenLoopSource s(csv_params(path));
  EXPECT_DOUBLE_EQ(s.update({}, {0.5, 0.0, 0.0}, nullptr).u, 0.5);
  EXPECT_DOUBLE_EQ(s.update({}, {1.5, 0.0, 0.0}, nullptr).u, -0.25);
  EXPECT_DOUBLE_EQ(s.force(0.5), 100.0);
}

// Bad files: std::invalid_argument with "FILE:LINE: ..." naming the bad value.
void expect_csv_error(const std::string& name, const std::string& text, const std::string& where_what) {
  const std::string path = write_file(name, text);
  try {
    OpenLoopSource s(csv_params(path));
    ADD_FAILURE() << name << ": accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), path + ":" + where_what) << name;
  }
}

TEST(OpenLoopCsv, MalformedFilesNameFileLineAndValue) {
  expect_csv_error("no_value_col.csv", "t,force\n0,1\n", "1: header 't,force' has no column 'force_N' or 'u'");
  expect_csv_error("no_t_col.csv", "time,force_N\n0,1\n", "1: header 'time,force_N' has no column 't'");
  expect_csv_error("short_row.csv", "t,force_N\n0,1\n0.5\n", "3: row '0.5' has 1 columns, the header names 2");
  expect_csv_error("empty_cell.csv", "t,force_N\n0,1\n0.5,\n", "3: force_N = '': not a finite number");
  expect_csv_error("abc.csv", "t,force_N\n0,1\n0.5,abc\n", "3: force_N = 'abc': not a finite number");
  expect_csv_error("nan.csv", "t,u\n0,nan\n", "2: u = 'nan': not a finite number");
  expect_csv_error("inf_t.csv", "t,u\n0,1\ninf,1\n", "3: t = 'inf': not a finite number");
  expect_csv_error("trailing.csv", "t,force_N\n0,1\n0.5,2x\n", "3: force_N = '2x': not a finite number");
  // Line numbers count comments and blank lines.
  expect_csv_error("decreasing.csv", "# c\nt,force_N\n0,1\n\n0.5,2\n0.4,3\n", "6: t = 0.4: times must increase strictly");
  expect_csv_error("repeated.csv", "t,force_N\n0,1\n0,2\n", "3: t = 0: times must increase strictly");
  expect_csv_error("no_rows.csv", "t,force_N\n# nothing\n", "2: no data rows");

  // A missing file has no line; the message names the key and the path.
  const std::string missing = ::testing::TempDir() + "feeddrive_open_loop_does_not_exist.csv";
  try {
    OpenLoopSource s(csv_params(missing));
    ADD_FAILURE() << "missing file accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "controller.file = '" + missing + "': cannot open the file");
  }
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
  expect_invalid(p, "controller.file = '': kind = csv needs a file");

  for (OpenLoopKind k : {OpenLoopKind::kStep, OpenLoopKind::kSine, OpenLoopKind::kRamp, OpenLoopKind::kCsv})
    EXPECT_EQ(open_loop_kind_from_string(to_string(k)), k);
  EXPECT_THROW(open_loop_kind_from_string("square"), std::invalid_argument);
}

}  // namespace
}  // namespace feeddrive::controller
