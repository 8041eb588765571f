// The streaming quantile (feeddrive/common/quantile.hpp) against the exact order statistic.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "feeddrive/common/quantile.hpp"

using feeddrive::stats::StreamingQuantile;

namespace {

// The documented bound: half a bucket, a bucket spanning a factor 1 + 2^-10 of a binade.
constexpr double kRelativeBound = 1.0 / 2048.0;

double exact_rank(std::vector<double> v, std::size_t k) {
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

void expect_all_ranks_within_bound(const std::vector<double>& v) {
  StreamingQuantile q;
  for (double x : v) q.add(x);
  ASSERT_EQ(q.count(), v.size());
  std::vector<double> sorted = v;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t k = 0; k < v.size(); k += std::max<std::size_t>(1, v.size() / 997)) {
    const double exact = sorted[k];
    EXPECT_LE(std::abs(q.value_at_rank(k) - exact), kRelativeBound * std::abs(exact)) << "rank " << k;
  }
  EXPECT_EQ(q.value_at_rank(0), sorted.front());
  EXPECT_EQ(q.value_at_rank(v.size() - 1), sorted.back());
}

}  // namespace

TEST(StreamingQuantile, WithinHalfABucketOfTheExactOrderStatistic) {
  std::mt19937_64 rng(42);
  // |e| of a tracking run spans decades: log-uniform over 1e-12 .. 1e-3
  std::uniform_real_distribution<double> decade(-12.0, -3.0);
  std::vector<double> v(200000);
  for (double& x : v) x = std::pow(10.0, decade(rng));
  expect_all_ranks_within_bound(v);
  // the p95 of the summary: rank floor(0.95 n)
  StreamingQuantile q;
  for (double x : v) q.add(x);
  const std::size_t k = static_cast<std::size_t>(0.95 * static_cast<double>(v.size()));
  const double exact = exact_rank(v, k);
  EXPECT_NEAR(q.value_at_rank(k), exact, kRelativeBound * exact);
}

TEST(StreamingQuantile, SignedValuesLikeLatenciesAndLeads) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> lead(-20.0, 300.0);  // microseconds, both signs
  std::vector<double> v(100000);
  for (double& x : v) x = std::round(lead(rng));
  expect_all_ranks_within_bound(v);
  StreamingQuantile q;
  for (double x : v) q.add(x);
  // the nearest-rank rule floor(p (n - 1)) of the monitor's latency statistics
  for (double p : {0.01, 0.5, 0.99}) {
    const double exact = exact_rank(v, static_cast<std::size_t>(p * static_cast<double>(v.size() - 1)));
    EXPECT_LE(std::abs(q.quantile(p) - exact), kRelativeBound * std::abs(exact)) << p;
  }
}

TEST(StreamingQuantile, ZerosNanAndEmpty) {
  StreamingQuantile q;
  EXPECT_TRUE(std::isnan(q.quantile(0.5)));
  for (int i = 0; i < 10; ++i) q.add(0.0);
  q.add(std::numeric_limits<double>::quiet_NaN());
  q.add(1.0);
  EXPECT_EQ(q.count(), 11u);
  EXPECT_EQ(q.nan_count(), 1u);
  EXPECT_EQ(q.value_at_rank(5), 0.0);  // the bucket holding zero is exact
  EXPECT_EQ(q.value_at_rank(10), 1.0);
}

TEST(StreamingQuantile, KeyOrderIsValueOrder) {
  const double vals[] = {-std::numeric_limits<double>::infinity(), -1e300, -1.5, -1e-310, -0.0, 0.0, 1e-310, 1.5, 1e300,
                         std::numeric_limits<double>::infinity()};
  for (std::size_t i = 0; i + 1 < std::size(vals); ++i) {
    EXPECT_LE(StreamingQuantile::key_of(vals[i]), StreamingQuantile::key_of(vals[i + 1])) << vals[i];
    EXPECT_EQ(StreamingQuantile::value_of(StreamingQuantile::key_of(vals[i])), vals[i]);
  }
}
