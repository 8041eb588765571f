#include "feeddrive/fit/replay.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/plant/effects.hpp"
#include "feeddrive/plant/plant.hpp"

namespace feeddrive::fit {

double rms(const Eigen::VectorXd& r, long n_active) {
  const long n = n_active > 0 ? n_active : r.size();
  return n ? std::sqrt(r.squaredNorm() / static_cast<double>(n)) : 0.0;
}

double window_length(const Record& rec, double window) {
  return window > 0 ? window : std::max(0.1, 20.0 * rec.period);
}

namespace {

// The bristle deflection z at a window start t_s where the drive sticks (the filter point nearest
// t_s masked: |v^| below stick_velocity over its kernel). z along the measured motion (in.z) is
// integrated from a smoothed velocity and leaves the static friction out of balance there by the
// filtered force residual r_i, r = m a - F + F_friction + ... (model.hpp): the replay would turn
// that into a creep of r_i / sigma_0 the drive did not make (1.7 um RMS, 70x the gap floor, on
// the closed-loop scenario's own record at rest under its 15 N constant force; issue 20's review).
// z - r_i / sigma_0 balances it (sigma_0 z is LuGre's static friction at rest: Canudas de Wit
// et al. 1995, eq. 1), held within the stiction level |sigma_0 z| <= F_s. A model without LuGre
// friction has no z: in.z[s] unchanged.
double bristle_at_rest(const Record& rec, const plant::PlantParams& pe, const Internal& in, long s) {
  const auto& f = pe.friction;
  const double z = in.z[static_cast<std::size_t>(s)];
  if (f.model != plant::FrictionModel::kLuGre || !(f.bristle_stiffness > 0) || in.unmasked.size() == 0) return z;
  const auto& tau = rec.bank.tau;
  const double t = rec.data->t[static_cast<std::size_t>(s)];
  const auto it = std::lower_bound(tau.begin(), tau.end(), t);
  std::size_t i = static_cast<std::size_t>(it - tau.begin());
  if (i == tau.size() || (i > 0 && t - tau[i - 1] < tau[i] - t)) i = i > 0 ? i - 1 : 0;
  if (i >= rec.masked.size() || !rec.masked[i]) return z;
  const double limit = f.static_force / f.bristle_stiffness;
  return std::clamp(z - in.unmasked[static_cast<long>(i)] / f.bristle_stiffness, -limit, limit);
}

}  // namespace

Replay replay(const Record& rec, const plant::PlantParams& model, double window, const interrupt::StopToken& stop) {
  const MeasuredData& d = *rec.data;
  const long n = static_cast<long>(d.size());
  const double W = window_length(rec, window);
  Internal in;
  force_residual(rec, model, &in);
  const plant::PlantParams pe = plant::effective_params(model);
  plant::PlantParams p = model;
  p.sensor = plant::SensorParams{};
  const double per_input = d.input_kind == InputKind::kCommand ? 1.0 : 1.0 / model.thrust_gain();
  Replay out;
  out.x_sim.assign(static_cast<std::size_t>(n), 0.0);
  out.error.assign(static_cast<std::size_t>(n), 0.0);
  double sum = 0.0;
  long count = 0;
  long s = 0;
  while (s + 1 < n) {
    stop.check();
    long e = s;
    while (e + 1 < n && d.t[e + 1] - d.t[s] <= W + 1e-12) ++e;
    if (e == s) e = s + 1;
    p.initial.position = rec.motion.x[s];
    p.initial.velocity = rec.motion.v[s];
    p.initial.bristle = bristle_at_rest(rec, pe, in, s);
    p.initial.grinding = in.fg[s];
    p.initial.current = 0.0;
    // With an input delay the commands held before the window still act in it.
    std::vector<std::pair<double, double>> history;
    if (p.effects.input_delay.enabled) {
      for (long k = s; k > 0 && d.t[s] - d.t[k] <= p.effects.input_delay.delay + rec.period; --k)
        history.insert(history.begin(), {d.t[k - 1], per_input * d.input[k - 1]});
    }
    plant::Plant drive(p, rec.period, d.t[s]);
    drive.prime_input_history(history);
    out.x_sim[s] = rec.motion.x[s];
    for (long k = s; k < e; ++k) {
      drive.advance(per_input * d.input[k], d.t[k + 1]);
      out.x_sim[k + 1] = drive.state().x;
    }
    // Initial position and velocity of the window: the least-squares correction
    // x_sim + a + b*(t - t_s) to the window's measurements (first-order sensitivity of a
    // moving mass to x(t_s), v(t_s)), so that noise in x^, v^ does not drift into the gap.
    double S0 = 0, S1 = 0, S2 = 0, E0 = 0, E1 = 0;
    for (long k = s; k <= e; ++k) {
      const double tau = d.t[k] - d.t[s], err = out.x_sim[k] - d.x[k];
      S0 += 1;
      S1 += tau;
      S2 += tau * tau;
      E0 += err;
      E1 += err * tau;
    }
    const double det = S0 * S2 - S1 * S1;
    const double a = det > 0 ? (S2 * E0 - S1 * E1) / det : 0.0;
    const double b = det > 0 ? (S0 * E1 - S1 * E0) / det : 0.0;
    for (long k = s; k <= e; ++k) {
      const double tau = d.t[k] - d.t[s];
      out.x_sim[k] -= a + b * tau;
      const double err = out.x_sim[k] - d.x[k];
      out.error[k] = err;
      if (k > s) {
        sum += err * err;
        ++count;
      }
    }
    s = e;
  }
  out.gap = count ? std::sqrt(sum / static_cast<double>(count)) : 0.0;
  return out;
}

namespace {

std::vector<Bin> bins(const std::vector<std::string>& labels, const std::vector<int>& which_point,
                      const Eigen::VectorXd& r, const std::vector<int>& which_sample, const Replay& rp) {
  std::vector<Bin> out(labels.size());
  double total = 0.0;
  long active = 0;
  for (int b : which_point) active += b >= 0 ? 1 : 0;
  for (std::size_t b = 0; b < labels.size(); ++b) out[b].label = labels[b];
  for (long i = 0; i < r.size(); ++i) {
    const int b = which_point[static_cast<std::size_t>(i)];
    if (b < 0) continue;
    out[b].points++;
    out[b].force_rms += r[i] * r[i];
    total += r[i] * r[i];
  }
  std::vector<double> gsum(labels.size(), 0.0);
  std::vector<long> gcount(labels.size(), 0);
  for (std::size_t k = 0; k < which_sample.size(); ++k) {
    const int b = which_sample[k];
    if (b < 0) continue;
    gsum[b] += rp.error[k] * rp.error[k];
    gcount[b]++;
  }
  for (std::size_t b = 0; b < labels.size(); ++b) {
    Bin& x = out[b];
    const double sq = x.force_rms;
    x.share = total > 0 ? sq / total : 0.0;
    x.force_rms = x.points ? std::sqrt(sq / static_cast<double>(x.points)) : 0.0;
    const double frac = static_cast<double>(x.points) / static_cast<double>(std::max<long>(1, active));
    x.concentration = frac > 0 ? x.share / frac : 0.0;
    x.gap = gcount[b] ? std::sqrt(gsum[b] / static_cast<double>(gcount[b])) : 0.0;
  }
  return out;
}

}  // namespace

Localisation localise(const Record& rec, const Eigen::VectorXd& r, const Replay& rp) {
  const MeasuredData& d = *rec.data;
  const Motion& m = rec.motion;
  const long n = static_cast<long>(d.size());
  const auto& bank = rec.bank;
  const double L = bank.half_width;
  const double v0 = std::max(1e-4, 0.02 * rec.v_max_abs);  // "near zero" velocity
  const double a0 = 0.1 * rec.a_max_abs;                   // "constant velocity" acceleration
  // per-sample classes
  std::vector<int> vel(n), acc(n), pos(n), tim(n);
  const int npos = 8, ntim = 10;
  const double t0 = d.t.front(), t1 = d.t.back(), range = std::max(rec.x_max - rec.x_min, 1e-12);
  // reversal: within +-3L of the sample the velocity is both above v0/2 and below -v0/2
  std::vector<char> reversal(n, 0);
  {
    const double R = 3.0 * L, vr = 0.5 * v0;
    long lo = 0, hi = 0;
    for (long k = 0; k < n; ++k) {
      while (d.t[k] - d.t[lo] > R) ++lo;
      while (hi + 1 < n && d.t[hi + 1] - d.t[k] <= R) ++hi;
      bool up = false, down = false;
      for (long j = lo; j <= hi; ++j) {
        up = up || m.v[j] > vr;
        down = down || m.v[j] < -vr;
      }
      reversal[k] = up && down;
    }
  }
  for (long k = 0; k < n; ++k) {
    const double v = m.v[k], a = m.a[k];
    vel[k] = reversal[k] ? 0 : (std::abs(v) < v0 ? 1 : 2);
    acc[k] = std::abs(a) < a0 ? 0 : (a * v > 0 ? 1 : 2);
    pos[k] = std::min(npos - 1, static_cast<int>((m.x[k] - rec.x_min) / range * npos));
    tim[k] = std::min(ntim - 1, static_cast<int>((d.t[k] - t0) / (t1 - t0) * ntim));
  }
  const auto at_points = [&](const std::vector<int>& cls) {
    std::vector<int> out(bank.tau.size());
    for (std::size_t i = 0; i < out.size(); ++i)
      out[i] = (i < rec.masked.size() && rec.masked[i]) ? -1 : cls[static_cast<std::size_t>(bank.nearest[i])];
    return out;
  };
  Localisation loc;
  char buf[96];
  std::vector<std::string> tl, pl;
  for (int b = 0; b < ntim; ++b) {
    std::snprintf(buf, sizeof buf, "t %.3g-%.3g s", t0 + (t1 - t0) * b / ntim, t0 + (t1 - t0) * (b + 1) / ntim);
    tl.push_back(buf);
  }
  for (int b = 0; b < npos; ++b) {
    std::snprintf(buf, sizeof buf, "x %.4g-%.4g mm", 1e3 * (rec.x_min + range * b / npos),
                  1e3 * (rec.x_min + range * (b + 1) / npos));
    pl.push_back(buf);
  }
  std::snprintf(buf, sizeof buf, "near zero velocity (below %.3g mm/s)", v0 * 1e3);
  loc.time = bins(tl, at_points(tim), r, tim, rp);
  loc.velocity = bins({"reversal", buf, "moving"}, at_points(vel), r, vel, rp);
  loc.acceleration = bins({"constant velocity", "accelerating", "decelerating"}, at_points(acc), r, acc, rp);
  loc.position = bins(pl, at_points(pos), r, pos, rp);
  // the most concentrated bin of each kind with enough points
  std::string s = "the force residual concentrates in: ";
  bool first = true;
  for (const auto* group : {&loc.velocity, &loc.acceleration, &loc.position, &loc.time}) {
    const Bin* best = nullptr;
    for (const Bin& b : *group)
      if (b.points >= 3 && (!best || b.concentration > best->concentration)) best = &b;
    if (!best) continue;
    std::snprintf(buf, sizeof buf, "%s%s (x%.2g, %.0f%% of it)", first ? "" : "; ", best->label.c_str(),
                  best->concentration, 100 * best->share);
    s += buf;
    first = false;
  }
  loc.summary = s;
  return loc;
}

}  // namespace feeddrive::fit
