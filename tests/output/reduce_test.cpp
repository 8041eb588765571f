// The plot reduction (output::MinMaxReducer) keeps, in every bucket, the global minimum and
// maximum of each curve, with their times, and writes them in time order.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <vector>

#include "feeddrive/output/plot_reduce.hpp"

using feeddrive::output::MinMaxReducer;
namespace fs = std::filesystem;

TEST(MinMaxReducer, KeepsTheMinimumAndMaximumOfEveryBucket) {
  // A chattering signal (a +-1 square wave at the sample rate) on a slow sine, plus rare
  // one-sample spikes: what a pixel column must show is the band and every spike.
  const long n = 1'000'000;
  const double T = 1e-5, t1 = static_cast<double>(n) * T;
  const std::size_t buckets = 1000;
  MinMaxReducer r(0.0, t1, buckets, 2);
  std::vector<double> lo(buckets, INFINITY), hi(buckets, -INFINITY), t_lo(buckets), t_hi(buckets);
  std::mt19937 rng(3);
  std::uniform_int_distribution<long> spike_at(0, n - 1);
  std::vector<long> spikes(20);
  for (long& s : spikes) s = spike_at(rng);
  std::vector<double> spike_value(spikes.size());
  for (long k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * T;
    double y[2] = {std::sin(2 * M_PI * t / t1) + ((k & 1) ? 1.0 : -1.0), std::cos(t)};
    for (std::size_t i = 0; i < spikes.size(); ++i)
      if (spikes[i] == k) spike_value[i] = y[0] += 50.0;
    r.add(t, y);
    // the reference extremes per bucket, by brute force (the bucket rule itself is bucket_of)
    const std::size_t b = r.bucket_of(t);
    if (y[0] < lo[b]) lo[b] = y[0], t_lo[b] = t;
    if (y[0] > hi[b]) hi[b] = y[0], t_hi[b] = t;
  }
  for (std::size_t b = 0; b < buckets; ++b) {
    const auto& e = r.at(b, 0);
    EXPECT_EQ(e.n, static_cast<std::uint64_t>(n / static_cast<long>(buckets)));
    EXPECT_EQ(e.y_min, lo[b]) << b;
    EXPECT_EQ(e.y_max, hi[b]) << b;
    EXPECT_EQ(e.t_min, t_lo[b]) << b;
    EXPECT_EQ(e.t_max, t_hi[b]) << b;
  }
  for (std::size_t i = 0; i < spikes.size(); ++i)
    EXPECT_GE(r.at(r.bucket_of(static_cast<double>(spikes[i]) * T), 0).y_max, spike_value[i]);
}

TEST(MinMaxReducer, WritesTwoRowsPerBucketInTimeOrderAndSkipsNan) {
  MinMaxReducer r(0.0, 4.0, 4, 2);
  const double nan = std::nan("");
  const double rows[][3] = {{0.1, 5.0, nan}, {0.5, -1.0, nan}, {1.2, -3.0, 2.0}, {1.7, 4.0, 1.0}, {3.9, 0.0, 7.0}};
  for (const auto& row : rows) r.add(row[0], row + 1);
  const fs::path p = fs::temp_directory_path() / ("reduce_test_" + std::to_string(::getpid()) + ".csv");
  r.write_csv(p, {"a", "b"});
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  fs::remove(p);
  // bucket 0: a's max (5 at 0.1) before its min (-1 at 0.5), b empty; bucket 1: a's min first,
  // b's max first; bucket 2 empty: no rows; bucket 3: one sample, written twice.
  EXPECT_EQ(ss.str(),
            "t_a,a,t_b,b\n"
            "0.1,5,nan,nan\n0.5,-1,nan,nan\n"
            "1.2,-3,1.2,2\n1.7,4,1.7,1\n"
            "3.9,0,3.9,7\n3.9,0,3.9,7\n");
}
