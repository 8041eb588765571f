#include "feeddrive/fit/signals.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace feeddrive::fit {

double order_statistic(std::vector<double> v, std::size_t k) {
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

double cubic_gap(const std::vector<double>& t, const std::vector<double>& x, std::size_t k, double* w2) {
  const std::size_t nb[4] = {k - 2, k - 1, k + 1, k + 2};
  double p = 0.0, sum2 = 0.0;
  for (std::size_t a = 0; a < 4; ++a) {
    double w = 1.0;
    for (std::size_t b = 0; b < 4; ++b)
      if (b != a) w *= (t[k] - t[nb[b]]) / (t[nb[a]] - t[nb[b]]);
    p += w * x[nb[a]];
    sum2 += w * w;
  }
  if (w2) *w2 = sum2;
  return x[k] - p;
}

double kernel(double s, double L) {
  const double u = s / L;
  if (u <= -1.0 || u >= 1.0) return 0.0;
  const double w = 1.0 - u * u;
  return 315.0 / (256.0 * L) * w * w * w * w;
}

// Hc = 1/2 + 315/256 * P(u),  P(u) = u - 4u^3/3 + 6u^5/5 - 4u^7/7 + u^9/9  (P(1) = 128/315).
double kernel_dd(double s, double L) {
  const double u = s / L;
  if (u <= -1.0 || u >= 1.0) return 0.0;
  const double w = 1.0 - u * u;
  return -8.0 * 315.0 / (256.0 * L) * w * w * (1.0 - 7.0 * u * u) / (L * L);
}

double kernel_cdf(double s, double L) {
  const double u = s / L;
  if (u <= -1.0) return 0.0;
  if (u >= 1.0) return 1.0;
  const double u2 = u * u;
  const double p = u * (1.0 + u2 * (-4.0 / 3.0 + u2 * (6.0 / 5.0 + u2 * (-4.0 / 7.0 + u2 / 9.0))));
  return 0.5 + 315.0 / 256.0 * p;
}

Motion estimate_motion(const std::vector<double>& t, const std::vector<double>& x, int half_window) {
  const long n = static_cast<long>(t.size());
  const long M = std::max(2, half_window);
  if (n < 2 * M + 1) throw std::invalid_argument("estimate_motion: fewer samples than one window");
  // Coefficients c of the local cubic of each sample, in the scaled variable s = (t - t_k)/h.
  std::vector<Eigen::Vector4d> coef(static_cast<std::size_t>(n));
  std::vector<double> scale(static_cast<std::size_t>(n));
  for (long k = 0; k < n; ++k) {
    const long lo = std::clamp(k - M, 0L, n - 1 - 2 * M);
    const long hi = lo + 2 * M;
    const double h = 0.5 * (t[hi] - t[lo]);
    Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
    Eigen::Vector4d b = Eigen::Vector4d::Zero();
    for (long j = lo; j <= hi; ++j) {
      const double s = (t[j] - t[k]) / h;
      const Eigen::Vector4d phi(1.0, s, s * s, s * s * s);
      A += phi * phi.transpose();
      b += phi * (x[j] - x[k]);  // relative to x_k: keeps the normal equations well scaled
    }
    coef[k] = A.ldlt().solve(b);
    coef[k][0] += x[k];
    scale[k] = h;
  }
  Motion m;
  m.x.resize(n);
  m.v.resize(n);
  m.a.resize(n);
  for (long k = 0; k < n; ++k) {
    const double h = scale[k];
    m.x[k] = coef[k][0];
    m.v[k] = coef[k][1] / h;
    m.a[k] = 2.0 * coef[k][2] / (h * h);
  }
  const auto eval = [&](long k, double tt, double& xv, double& vv) {
    const double h = scale[k], s = (tt - t[k]) / h;
    const Eigen::Vector4d& c = coef[k];
    xv = c[0] + s * (c[1] + s * (c[2] + s * c[3]));
    vv = (c[1] + s * (2.0 * c[2] + s * 3.0 * c[3])) / h;
  };
  m.x_mid.resize(n - 1);
  m.v_mid.resize(n - 1);
  m.t_mid.resize(n - 1);
  m.dt.resize(n - 1);
  for (long j = 0; j + 1 < n; ++j) {
    const double tm = 0.5 * (t[j] + t[j + 1]);
    double x0, v0, x1, v1;
    eval(j, tm, x0, v0);
    eval(j + 1, tm, x1, v1);
    m.x_mid[j] = 0.5 * (x0 + x1);
    m.v_mid[j] = 0.5 * (v0 + v1);
    m.t_mid[j] = tm;
    m.dt[j] = t[j + 1] - t[j];
  }
  return m;
}

FilterBank make_filter_bank(const std::vector<double>& t, const std::vector<double>& x, double half_width) {
  const double L = half_width;
  const long n = static_cast<long>(t.size());
  FilterBank b;
  b.half_width = L;
  for (double tau = t.front() + L; tau + L <= t.back(); tau += 2.0 * L) b.tau.push_back(tau);
  if (b.tau.size() < 4)
    throw std::invalid_argument("the record (" + std::to_string(t.back() - t.front()) +
                                " s) is shorter than 4 filter windows of " + std::to_string(2 * L) + " s");
  std::vector<Eigen::Triplet<double>> trip;
  b.accel.resize(b.tau.size());
  b.nearest.resize(b.tau.size());
  for (std::size_t i = 0; i < b.tau.size(); ++i) {
    const double tau = b.tau[i];
    // intervals [t_j, t_j+1] that meet [tau - L, tau + L]
    long j0 = static_cast<long>(std::upper_bound(t.begin(), t.end(), tau - L) - t.begin()) - 1;
    j0 = std::max(0L, j0);
    long j1 = static_cast<long>(std::lower_bound(t.begin(), t.end(), tau + L) - t.begin());
    j1 = std::min(n - 1, j1);
    double acc = 0.0;
    for (long j = j0; j < j1; ++j) {
      const double w = kernel_cdf(tau - t[j], L) - kernel_cdf(tau - t[j + 1], L);
      if (w != 0.0) trip.emplace_back(static_cast<int>(i), static_cast<int>(j), w);
      // x piecewise linear between samples: Int h''(tau-t) x dt = sum_j slope_j [h(tau-t_j) - h(tau-t_j+1)]
      const double slope = (x[j + 1] - x[j]) / (t[j + 1] - t[j]);
      acc += slope * (kernel(tau - t[j], L) - kernel(tau - t[j + 1], L));
    }
    b.accel[i] = acc;
    const long k = static_cast<long>(std::lower_bound(t.begin(), t.end(), tau) - t.begin());
    b.nearest[i] = (k > 0 && (k == n || tau - t[k - 1] < t[k] - tau)) ? k - 1 : std::min(k, n - 1);
  }
  b.w.resize(static_cast<int>(b.tau.size()), static_cast<int>(n - 1));
  b.w.setFromTriplets(trip.begin(), trip.end());
  return b;
}

Eigen::VectorXd apply(const FilterBank& b, const Eigen::VectorXd& f) { return b.w * f; }

Eigen::VectorXd apply_delayed(const FilterBank& b, const std::vector<double>& t, const Eigen::VectorXd& u,
                              double delay) {
  const double L = b.half_width;
  const long n = static_cast<long>(t.size());
  Eigen::VectorXd out(static_cast<long>(b.tau.size()));
  for (std::size_t i = 0; i < b.tau.size(); ++i) {
    const double tau = b.tau[i];
    // before t_0 + delay the held value is unknown: take u_0 (the record starts mid-hold)
    double acc = u[0] * (1.0 - kernel_cdf(tau - t[0] - delay, L));
    long j0 = static_cast<long>(std::upper_bound(t.begin(), t.end(), tau - L - delay) - t.begin()) - 1;
    j0 = std::max(0L, j0);
    long j1 = static_cast<long>(std::lower_bound(t.begin(), t.end(), tau + L - delay) - t.begin());
    j1 = std::min(n - 1, j1);
    for (long j = j0; j < j1; ++j)
      acc += u[j] * (kernel_cdf(tau - t[j] - delay, L) - kernel_cdf(tau - t[j + 1] - delay, L));
    // the last sample's value is held after t_n-1 (only reached with a delay)
    if (j1 == n - 1) acc += u[n - 1] * kernel_cdf(tau - t[n - 1] - delay, L);
    out[static_cast<long>(i)] = acc;
  }
  return out;
}

}  // namespace feeddrive::fit
