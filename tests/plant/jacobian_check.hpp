#pragma once
// The central-difference check of the analytic Jacobian (dynamics.hpp: jacobian() against
// derivative()), one place for forces_test.cpp and effects_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>

#include "feeddrive/plant/dynamics.hpp"

namespace feeddrive::plant::test {

/// Checks jacobian(p, s, u) against central differences of derivative(p, ., u) on 200 random
/// states drawn with `seed` (x in +-0.05 m, v in +-v_max, z in +-5e-5 m, F_g in +-50 N, i in
/// +-5 A; u in +-3 V). Step h_j = 1e-6 * scale_j with scale = (1e-2, 1e-1, 1e-5, 10, 1); the
/// tolerance 1e-5 relative covers the O(h^2) truncation, 1e-14*|f|/h the round-off (~1e-15*|f|/h)
/// of the difference quotient, 1e-12 an entry that is 0. `each(s, u, J)`, when given, adds the
/// caller's checks on every state.
inline void expect_jacobian_matches_differences(
    const PlantParams& p, std::uint64_t seed, double v_max,
    const std::function<void(const State&, double, const Jacobian&)>& each = {}) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ux(-0.05, 0.05), uv(-v_max, v_max), uz(-5e-5, 5e-5), ufg(-50, 50), ui(-5, 5),
      uu(-3, 3);
  const StateVector scale{1e-2, 1e-1, 1e-5, 10.0, 1.0};
  for (int trial = 0; trial < 200; ++trial) {
    const State s{ux(rng), uv(rng), uz(rng), ufg(rng), ui(rng)};
    const double u = uu(rng);
    const Jacobian J = jacobian(p, s, u);
    if (each) each(s, u, J);
    for (int c = 0; c < kStateSize; ++c) {
      const double h = 1e-6 * scale[c];
      StateVector yp = s.to_vector(), ym = s.to_vector();
      yp[c] += h;
      ym[c] -= h;
      const StateVector fp = derivative(p, State::from_vector(yp), u);
      const StateVector fm = derivative(p, State::from_vector(ym), u);
      for (int r = 0; r < kStateSize; ++r) {
        const double fd = (fp[r] - fm[r]) / (2 * h);
        const double tol = 1e-5 * std::abs(J[r][c]) + 1e-14 * std::max(std::abs(fp[r]), std::abs(fm[r])) / h + 1e-12;
        EXPECT_NEAR(J[r][c], fd, tol) << "trial " << trial << " row " << r << " col " << c;
      }
    }
  }
}

}  // namespace feeddrive::plant::test
