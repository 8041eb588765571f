#pragma once
// Signal processing of feeddrive-fit: motion estimates from a quantized position record, and the
// "modulating function" filter that turns the equation of motion into a force balance that needs
// no numerical differentiation of noisy data (docs/fit.md, "Force residual").
//
// Motion estimates: at every sample k a cubic is fitted by least squares to the M samples on each
// side (local polynomial regression on the actual, possibly jittered, time stamps); its value and
// first two derivatives at t are x^, v^, a^ (Savitzky & Golay 1964 for uniform times).
//
// Filter: the kernel h(s) = 315/(256 L) (1 - (s/L)^2)^4 on |s| <= L (unit area, h and h' vanish
// at +-L). For the equation m x'' = F(t), integrating against h(tau - t) and by parts twice gives
//     m * Int h''(tau - t) x(t) dt = Int h(tau - t) F(t) dt
// (Shinbrot 1957, "method of modulating functions"): the left side uses the raw positions (no
// derivative of data is taken), the right side filters every force with the same h. Forces are
// treated as held over each sample interval [t_j, t_j+1) (the input is a zero-order hold), so the
// right side is  sum_j F_j * w_j(tau),  w_j(tau) = Hc(tau - t_j) - Hc(tau - t_j+1),  Hc = Int h.

#include <Eigen/SparseCore>
#include <vector>

namespace feeddrive::fit {

/// h(s), h''(s) and Hc(s) = Int_{-inf}^{s} h of the kernel above, half-width L [s] (h'' gives
/// the noise floor's discretisation term, verdict.cpp).
double kernel(double s, double L);
double kernel_dd(double s, double L);
double kernel_cdf(double s, double L);

/// x^, v^, a^ at every sample and at the midpoint of every interval (size n-1).
struct Motion {
  std::vector<double> x, v, a;       ///< at the samples [m, m/s, m/s^2]
  std::vector<double> x_mid, v_mid;  ///< at the interval midpoints (t_j + t_j+1)/2
  std::vector<double> t_mid;         ///< interval midpoints [s]
  std::vector<double> dt;            ///< interval lengths t_j+1 - t_j [s]
};
/// The k-th smallest value of v (0-based, k < v.size()).
double order_statistic(std::vector<double> v, std::size_t k);

/// x_k less the cubic through its four neighbours k-2, k-1, k+1, k+2 at t_k (Lagrange, on the
/// stamps as they are; 2 <= k, k + 2 < x.size()): an isolated error e_k of sample k shows in full,
/// a smooth motion hardly. If w2 != nullptr it receives the sum of the cubic's squared weights
/// (34/36 on equal steps), so that independent errors of variance s^2 give (1 + w2) s^2.
double cubic_gap(const std::vector<double>& t, const std::vector<double>& x, std::size_t k, double* w2 = nullptr);

/// half_window: M, the samples on each side of the local cubic (>= 2).
Motion estimate_motion(const std::vector<double>& t, const std::vector<double>& x, int half_window);

/// The filter evaluated at points tau_i = t_0 + L + i*2L (non-overlapping supports, so the
/// filtered noise of different points is independent).
struct FilterBank {
  double half_width{0.0};                          ///< L [s]
  std::vector<double> tau;                         ///< evaluation times [s]
  std::vector<long> nearest;                       ///< sample index nearest to each tau
  Eigen::SparseMatrix<double, Eigen::RowMajor> w;  ///< w(i, j) = weight of interval j at tau_i
  std::vector<double> accel;                       ///< Int h''(tau_i - t) x(t) dt = filtered x'' [m/s^2]
};
/// Builds the bank for samples t, x; throws std::invalid_argument if the record holds fewer
/// than 4 filter windows.
FilterBank make_filter_bank(const std::vector<double>& t, const std::vector<double>& x, double half_width);

/// Filtered series of per-interval values f_j (size n-1): out_i = sum_j w(i,j) f_j.
Eigen::VectorXd apply(const FilterBank& b, const Eigen::VectorXd& f);

/// Per-interval weights of a signal held over [t_j + d, t_j+1 + d) (the thrust of a delayed
/// input), at the bank's points: the filtered delayed input is sum_j W_d(i,j) u_j.
Eigen::VectorXd apply_delayed(const FilterBank& b, const std::vector<double>& t, const Eigen::VectorXd& u,
                              double delay);

}  // namespace feeddrive::fit
