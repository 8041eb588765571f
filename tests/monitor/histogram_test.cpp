// The latency histograms of summary.json (monitor/histogram.hpp): bins, overflow, NaN, and the
// period-start lateness of real-time states against hand-made receive times.
#include "feeddrive/monitor/histogram.hpp"

#include <gtest/gtest.h>

#include <limits>

using namespace feeddrive::monitor;

TEST(Histogram, BinsOverflowAndNaN) {
  Histogram h(5.0, 4);
  for (const double x : {-3.0, 0.0, 4.99, 5.0, 19.9, 20.0, 1e6, std::numeric_limits<double>::quiet_NaN()}) h.add(x);
  ASSERT_EQ(h.counts().size(), 4u);
  EXPECT_EQ(h.counts()[0], 3);  // -3 (negative: first bin), 0, 4.99
  EXPECT_EQ(h.counts()[1], 1);  // 5
  EXPECT_EQ(h.counts()[2], 0);
  EXPECT_EQ(h.counts()[3], 1);  // 19.9
  EXPECT_EQ(h.overflow(), 2);   // 20 (= 4 bins * 5 us) and 1e6
  EXPECT_EQ(h.samples(), 7);    // NaN skipped
  EXPECT_THROW(Histogram(0.0, 4), std::invalid_argument);
}

TEST(Histogram, Csv) {
  Histogram a(5.0, 2), b(5.0, 2);
  a.add(1.0);
  a.add(6.0);
  b.add(6.0);
  EXPECT_EQ(histograms_csv({"x", "y"}, {a, b}), "bin_start_us,x,y\n0,1,0\n5,1,1\n");
}
