// The latency histograms of summary.json (monitor/histogram.hpp): bins, overflow, NaN, and the
// period-start lateness of real-time states against hand-made receive times.
#include "feeddrive/monitor/histogram.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace feeddrive::monitor;

TEST(Histogram, BinsOverflowAndNaN) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Histogram h = histogram({-3.0, 0.0, 4.99, 5.0, 19.9, 20.0, 1e6, nan}, 5.0, 4);
  ASSERT_EQ(h.counts.size(), 4u);
  EXPECT_EQ(h.counts[0], 3);  // -3 (negative: first bin), 0, 4.99
  EXPECT_EQ(h.counts[1], 1);  // 5
  EXPECT_EQ(h.counts[2], 0);
  EXPECT_EQ(h.counts[3], 1);  // 19.9
  EXPECT_EQ(h.overflow, 2);   // 20 (= 4 bins * 5 us) and 1e6
  EXPECT_EQ(h.samples, 7);    // NaN skipped
  EXPECT_THROW(histogram({1.0}, 0.0, 4), std::invalid_argument);
}

TEST(Histogram, PeriodStartLateness) {
  // T = 100 us; the states go out at 1000 + k*T plus a lateness of 0, 0, 7, 0, 30 us; state 0
  // (the start handshake, long before the clock starts) is ignored, as is a state not received.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> recv = {10.0, 1100.0, 1207.0, nan, 1430.0, 1500.0};
  const std::vector<double> late = period_start_lateness(recv, 100.0);
  ASSERT_EQ(late.size(), recv.size());
  EXPECT_TRUE(std::isnan(late[0]));
  EXPECT_TRUE(std::isnan(late[3]));
  EXPECT_DOUBLE_EQ(late[1], 0.0);
  EXPECT_DOUBLE_EQ(late[2], 7.0);
  EXPECT_DOUBLE_EQ(late[4], 30.0);
  EXPECT_DOUBLE_EQ(late[5], 0.0);
}

TEST(Histogram, Csv) {
  const Histogram a = histogram({1.0, 6.0}, 5.0, 2), b = histogram({6.0}, 5.0, 2);
  EXPECT_EQ(histograms_csv({"x", "y"}, {a, b}), "bin_start_us,x,y\n0,1,0\n5,1,1\n");
}
