// Waypoint references: a natural cubic spline through (t_i, x_i). The points come from the
// scenario layer (sim/src/scenario.cpp, read_waypoints_file, reads the CSV with feeddrive::csv).
//
// Spline: e.g. Burden & Faires, "Numerical Analysis", 9th ed., Sec. 3.5 "Cubic Spline
// Interpolation"; de Boor, "A Practical Guide to Splines", Ch. IV. Knots t_0 < ... < t_n, h_i =
// t_{i+1} - t_i, unknown second derivatives M_i = x''(t_i) with the natural end conditions M_0 =
// M_n = 0 and, for i = 1..n-1, the tridiagonal (strictly diagonally dominant) system
//   h_{i-1} M_{i-1} + 2 (h_{i-1} + h_i) M_i + h_i M_{i+1}
//       = 6 ((x_{i+1} - x_i)/h_i - (x_i - x_{i-1})/h_{i-1}),
// solved by the Thomas algorithm (no pivoting needed). On [t_i, t_{i+1}), with u = t - t_i:
//   x = x_i + b_i u + (M_i/2) u^2 + d_i u^3,   b_i = (x_{i+1} - x_i)/h_i - h_i (2 M_i + M_{i+1})/6,
//   d_i = (M_{i+1} - M_i)/(6 h_i);  v = b_i + M_i u + 3 d_i u^2,  a = M_i + 6 d_i u,  j = 6 d_i.
// Written in u from the left knot, x(t_i) = x_i exactly. With two points M = 0: a straight line.
// Outside [t_0, t_n] the sample is the end value with zero derivatives.

#include <algorithm>
#include <cmath>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "check.hpp"
#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::trajectory {
namespace {

constexpr std::size_t kMinPoints = 2;  // a spline needs at least one interval

class Waypoints final : public Trajectory {
 public:
  explicit Waypoints(std::vector<Waypoint> points) : p_(std::move(points)) {
    const std::size_t n = p_.size() - 1;  // number of intervals
    std::vector<double> h(n);
    for (std::size_t i = 0; i < n; ++i) h[i] = p_[i + 1].t - p_[i].t;
    m_.assign(n + 1, 0.0);  // natural ends: M_0 = M_n = 0
    if (n >= 2) {
      // Thomas algorithm on the interior unknowns M_1..M_{n-1}.
      std::vector<double> diag(n + 1, 0.0);
      std::vector<double> rhs(n + 1, 0.0);
      for (std::size_t i = 1; i < n; ++i) {
        diag[i] = 2.0 * (h[i - 1] + h[i]);
        rhs[i] = 6.0 * ((p_[i + 1].x - p_[i].x) / h[i] - (p_[i].x - p_[i - 1].x) / h[i - 1]);
      }
      for (std::size_t i = 2; i < n; ++i) {  // forward elimination (sub-diagonal h_{i-1})
        const double w = h[i - 1] / diag[i - 1];
        diag[i] -= w * h[i - 1];
        rhs[i] -= w * rhs[i - 1];
      }
      for (std::size_t i = n - 1; i >= 1; --i) {  // back substitution (super-diagonal h_i)
        m_[i] = (rhs[i] - h[i] * m_[i + 1]) / diag[i];
      }
    }
    b_.resize(n);
    d_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      b_[i] = (p_[i + 1].x - p_[i].x) / h[i] - h[i] * (2.0 * m_[i] + m_[i + 1]) / 6.0;
      d_[i] = (m_[i + 1] - m_[i]) / (6.0 * h[i]);
    }
  }

  Sample sample(double t) const override {
    if (std::isnan(t)) return detail::nan_sample();
    if (t < p_.front().t) return {p_.front().x, 0.0, 0.0, 0.0};
    if (t >= p_.back().t) return {p_.back().x, 0.0, 0.0, 0.0};
    // Interval i with t_i <= t < t_{i+1}.
    const auto it =
        std::upper_bound(p_.begin(), p_.end(), t, [](double value, const Waypoint& w) { return value < w.t; });
    const std::size_t i = static_cast<std::size_t>(std::distance(p_.begin(), it)) - 1;
    const double u = t - p_[i].t;
    const double c = 0.5 * m_[i];
    return {p_[i].x + u * (b_[i] + u * (c + u * d_[i])), b_[i] + u * (m_[i] + 3.0 * d_[i] * u), m_[i] + 6.0 * d_[i] * u,
            6.0 * d_[i]};
  }
  double end_time() const override { return p_.back().t; }

 private:
  std::vector<Waypoint> p_;
  std::vector<double> m_;  // M_i = x''(t_i) [m/s^2]
  std::vector<double> b_;  // x'(t_i) on interval i [m/s]
  std::vector<double> d_;  // x'''/6 on interval i [m/s^3]
};

}  // namespace

std::unique_ptr<Trajectory> make_waypoints(const std::vector<Waypoint>& points) {
  if (points.size() < kMinPoints)
    throw std::invalid_argument("waypoints: need at least 2 points, got " + std::to_string(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::string key = "waypoints[" + std::to_string(i) + "]";
    detail::require_finite(key + ".t", points[i].t);
    detail::require_finite(key + ".x", points[i].x);
    if (i > 0 && !(points[i].t > points[i - 1].t))
      detail::fail(key + ".t", points[i].t,
                   "must be greater than the previous t = " + detail::format_number(points[i - 1].t));
  }
  return std::make_unique<Waypoints>(points);
}

}  // namespace feeddrive::trajectory
