#include "feeddrive/fit/model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "feeddrive/plant/effects.hpp"
#include "feeddrive/plant/forces.hpp"

namespace feeddrive::fit {

Record prepare(const MeasuredData& d, const RecordOptions& opt) {
  Record r;
  r.data = &d;
  r.cache = std::make_shared<Record::Cache>();
  r.period = d.median_period();
  const int M =
      opt.motion_half_window > 0 ? opt.motion_half_window : std::max(3, static_cast<int>(std::lround(2e-3 / r.period)));
  const double L = opt.filter_half_width > 0 ? opt.filter_half_width : std::max(0.01, 10.0 * r.period);
  // A filter window must hold samples: one shorter than two sample periods averages nothing
  // (the force is the raw second difference) and makes a bank of one window per sample.
  if (opt.filter_half_width > 0 && opt.filter_half_width < 2.0 * r.period) {
    char why[200];
    std::snprintf(why, sizeof why,
                  ": --filter-half-width %.3g s is shorter than 2 sample periods (%.3g s) of the record; "
                  "use at least %.3g s, or 0 for the default",
                  opt.filter_half_width, r.period, 2.0 * r.period);
    throw DataError(d.source + why);
  }
  if (d.size() < static_cast<std::size_t>(2 * M + 1))
    throw DataError(d.source + ": " + std::to_string(d.size()) + " samples: too few for the motion estimate");
  r.motion = estimate_motion(d.t, d.x, M);
  try {
    r.bank = make_filter_bank(d.t, d.x, L);
  } catch (const std::invalid_argument& e) {
    throw DataError(d.source + ": " + e.what() + " (too few samples for the fit)");
  }
  // Finite samples can still be too large to fit (a position outlier of 1e200 m or 1e308 m):
  // the estimated velocity and acceleration and the filtered acceleration must have finite
  // squares (|y| < 1e150), else the fit fails later on a NaN or a CVODE error blamed on a model
  // key, or writes an infinite gap. Named with the sample that led there.
  const auto not_finite = [](const std::vector<double>& v) {
    return std::find_if(v.begin(), v.end(), [](double y) { return !(std::abs(y) < 1e150); }) - v.begin();
  };
  const long bad_v = not_finite(r.motion.v), bad_a = not_finite(r.motion.a), bad_f = not_finite(r.bank.accel);
  const long n = static_cast<long>(d.size());
  if (bad_v < n || bad_a < n || bad_f < static_cast<long>(r.bank.accel.size())) {
    const long k = bad_v < n ? bad_v : bad_a < n ? bad_a : r.bank.nearest[static_cast<std::size_t>(bad_f)];
    // the largest |x| within the estimate's reach of sample k
    long worst = k;
    for (long j = std::max(0L, k - 2 * M - 1); j < std::min(n, k + 2 * M + 2); ++j)
      if (std::abs(d.x[static_cast<std::size_t>(j)]) > std::abs(d.x[static_cast<std::size_t>(worst)])) worst = j;
    char why[240];
    std::snprintf(why, sizeof why,
                  ": the velocity or acceleration estimated from the position is beyond 1e150 near t = %.6g s "
                  "(position %.6g m at t = %.6g s): is the position column in metres and free of outliers?",
                  d.t[static_cast<std::size_t>(k)], d.x[static_cast<std::size_t>(worst)],
                  d.t[static_cast<std::size_t>(worst)]);
    throw DataError(d.source + why);
  }
  r.input.resize(static_cast<long>(d.size()) - 1);
  for (long j = 0; j + 1 < static_cast<long>(d.size()); ++j) r.input[j] = d.input[static_cast<std::size_t>(j)];
  const auto [xmin, xmax] = std::minmax_element(d.x.begin(), d.x.end());
  r.x_min = *xmin;
  r.x_max = *xmax;
  for (std::size_t k = 0; k < d.size(); ++k) {
    r.v_max_abs = std::max(r.v_max_abs, std::abs(r.motion.v[k]));
    r.a_max_abs = std::max(r.a_max_abs, std::abs(r.motion.a[k]));
  }
  return r;
}

long Record::active_points() const {
  long n = static_cast<long>(bank.tau.size());
  for (char m : masked) n -= m ? 1 : 0;
  return n;
}

double stick_velocity(const plant::PlantParams& model) {
  return std::max(1e-4, 20.0 * model.friction.static_smoothing_velocity);
}

void mask_stiction(Record& r, const plant::PlantParams& model) {
  r.masked.assign(r.bank.tau.size(), 0);
  const double vs = stick_velocity(model);
  const auto& v = r.motion.v;
  for (int i = 0; i < r.bank.w.outerSize(); ++i)
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(r.bank.w, i); it; ++it) {
      const long j = it.col();
      if (std::abs(v[j]) < vs && std::abs(v[j + 1]) < vs) r.masked[i] = 1;
    }
}

double thrust_per_input(const Record& r, const plant::PlantParams& p) {
  return r.data->input_kind == InputKind::kCommand ? p.thrust_gain() : 1.0;
}

namespace {

// z after h seconds at velocity v held (exact solution of the linear ODE for constant v).
double advance_z(const plant::FrictionParams& f, double z, double v, double h) {
  if (f.model != plant::FrictionModel::kLuGre || v == 0.0) return z;
  const double g = plant::stribeck(f, v);
  const double a = f.bristle_stiffness * std::abs(v) / g;
  const double zss = v / a;
  return zss + (z - zss) * std::exp(-a * h);
}

double advance_fg(const plant::GrindingParams& g, double fg, double x, double v, double h) {
  if (!g.enabled) return fg;
  const double C = g.damping();
  const double fss = plant::contact_fraction(g, x) * C * v;
  return fss + (fg - fss) * std::exp(-g.stiffness / C * h);
}

// Friction (part 0) or grinding (part 1) force averaged over each interval, with the internal
// state at the samples. Friction and grinding depend on v through fast internal states (and,
// for the static model, on sgn v), so they are averaged over S sub-steps with v^ and x^
// interpolated by the parabola through the interval's ends and midpoint; 32 sub-steps where
// v^ changes sign (a reversal inside the interval), 8 where it is small, 4 elsewhere.
void internal_force(const Record& r, const plant::PlantParams& pe, int part, Eigen::VectorXd& force,
                    std::vector<double>& state) {
  const Motion& m = r.motion;
  const long n = static_cast<long>(m.x.size());
  force.resize(n - 1);
  state.assign(static_cast<std::size_t>(n), 0.0);
  if ((part == 0 && pe.friction.model == plant::FrictionModel::kNone) || (part == 1 && !pe.grinding.enabled)) {
    force.setZero();
    if (part == 1) std::fill(state.begin(), state.end(), pe.initial.grinding);
    return;
  }
  double y = part == 0 ? pe.initial.bristle : pe.initial.grinding;
  state[0] = y;
  const double slow_velocity = std::max(1e-4, 100.0 * pe.friction.static_smoothing_velocity);
  for (long j = 0; j + 1 < n; ++j) {
    const double x = m.x_mid[j], v = m.v_mid[j], h = m.dt[j];
    const double v0 = m.v[j], v1 = m.v[j + 1];
    const double x0 = m.x[j], x1 = m.x[j + 1];
    const bool reversal = (v0 > 0) != (v1 > 0);
    const bool slow = std::min(std::abs(v0), std::abs(v1)) < slow_velocity;
    const int S = reversal ? 32 : slow ? 8 : 4;
    const double hs = h / S;
    double fsum = 0.0;
    for (int q = 0; q < S; ++q) {
      const double sq = (q + 0.5) / S;                          // sub-step midpoint in [0, 1]
      const auto par = [sq](double y0, double ym, double y1) {  // parabola through (0,y0), (1/2,ym), (1,y1)
        return y0 * (2 * sq - 1) * (sq - 1) + ym * 4 * sq * (1 - sq) + y1 * sq * (2 * sq - 1);
      };
      const double vs = par(v0, v, v1), xs = par(x0, x, x1);
      if (part == 0) {
        y = advance_z(pe.friction, y, vs, 0.5 * hs);
        fsum += plant::friction_force(pe.friction, vs, y);
        y = advance_z(pe.friction, y, vs, 0.5 * hs);
      } else {
        y = advance_fg(pe.grinding, y, xs, vs, 0.5 * hs);
        fsum += plant::grinding_force(pe.grinding, xs, y);
        y = advance_fg(pe.grinding, y, xs, vs, 0.5 * hs);
      }
    }
    force[j] = fsum / S;
    state[static_cast<std::size_t>(j + 1)] = y;
  }
}

}  // namespace

Eigen::VectorXd force_residual(const Record& r, const plant::PlantParams& p, Internal* internal) {
  const plant::PlantParams pe = plant::effective_params(p);
  const MeasuredData& d = *r.data;
  const long n = static_cast<long>(d.size());
  const double gain = thrust_per_input(r, pe);
  const double delay = p.effects.input_delay.enabled ? p.effects.input_delay.delay : 0.0;
  const Motion& m = r.motion;

  // Friction along the motion is the costly part and the same for every candidate that does
  // not change the friction model: it is cached (filtered) with the params it was computed for.
  Record::Cache& c = *r.cache;
  const auto refresh = [&](int part, bool& valid, Eigen::VectorXd& filtered, std::vector<double>& state) {
    Eigen::VectorXd f;
    internal_force(r, pe, part, f, state);
    filtered = apply(r.bank, f);
    valid = true;
  };
  if (!c.friction_valid || !fields::same(c.friction, pe.friction) || c.bristle0 != pe.initial.bristle) {
    refresh(0, c.friction_valid, c.friction_filtered, c.z);
    c.friction = pe.friction;
    c.bristle0 = pe.initial.bristle;
  }
  if (!c.grinding_valid || !fields::same(c.grinding, pe.grinding) || c.grinding0 != pe.initial.grinding) {
    refresh(1, c.grinding_valid, c.grinding_filtered, c.fg);
    c.grinding = pe.grinding;
    c.grinding0 = pe.initial.grinding;
  }
  if (internal) {
    internal->z = c.z;
    internal->fg = c.fg;
  }
  Eigen::VectorXd force(n - 1);
  long held = 0;  // index of the input held at t_mid - delay
  for (long j = 0; j + 1 < n; ++j) {
    const double x = m.x_mid[j], v = m.v_mid[j];
    double thrust;
    if (delay > 0.0) {
      const double ts = m.t_mid[j] - delay;
      while (held + 1 < n && d.t[held + 1] <= ts) ++held;
      thrust = gain * r.input[std::min(held, n - 2)];
    } else {
      thrust = gain * r.input[j];
    }
    force[j] = plant::ripple_force(pe.ripple, x, thrust) + plant::extra_force(pe, x, v, thrust);
  }
  Eigen::VectorXd thrust_f;
  if (delay > 0.0) {
    thrust_f = apply_delayed(r.bank, d.t, gain * r.input, delay);
  } else {
    thrust_f = apply(r.bank, gain * r.input);
  }
  const Eigen::Map<const Eigen::VectorXd> accel(r.bank.accel.data(), static_cast<long>(r.bank.accel.size()));
  Eigen::VectorXd res = pe.mass * accel - thrust_f + c.friction_filtered + c.grinding_filtered + apply(r.bank, force);
  if (internal) internal->unmasked = res;
  for (std::size_t i = 0; i < r.masked.size(); ++i)
    if (r.masked[i]) res[static_cast<long>(i)] = 0.0;
  return res;
}

}  // namespace feeddrive::fit
