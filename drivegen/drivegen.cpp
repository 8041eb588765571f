#include "drivegen.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>

namespace fdgen {
namespace {

constexpr double kPi = 3.14159265358979323846;
// The time stamps are recorded with an error uniform in +-kStampError [s] (1 sigma: kStampError/sqrt(3)).
constexpr double kStampError = 1e-6;

struct Rng {
  std::mt19937_64 g;
  double u(double a, double b) { return std::uniform_real_distribution<double>(a, b)(g); }
  bool coin(double p) { return u(0.0, 1.0) < p; }
  double sign() { return coin(0.5) ? 1.0 : -1.0; }
};

// ---- the reference: piecewise segments, each gives x, v, a at a time inside it ----------------
struct Segment {
  double t0, t1;
  std::function<void(double, double&, double&, double&)> eval;  // time since t0 -> x, v, a
};

// Trapezoidal (or triangular) move of signed distance d from x0 with speed vm and acceleration am.
Segment move(double t0, double x0, double d, double vm, double am) {
  const double D = std::abs(d), s = d < 0 ? -1.0 : 1.0;
  double ta = vm / am;
  if (am * ta * ta > D) {  // triangle
    ta = std::sqrt(D / am);
    vm = am * ta;
  }
  const double tc = (D - am * ta * ta) / vm;
  const double T = 2 * ta + tc;
  return {t0, t0 + T, [=](double t, double& x, double& v, double& a) {
            double p, q, r;
            if (t < ta) {
              p = 0.5 * am * t * t, q = am * t, r = am;
            } else if (t < ta + tc) {
              p = 0.5 * am * ta * ta + vm * (t - ta), q = vm, r = 0;
            } else if (t < T) {
              const double u = T - t;
              p = D - 0.5 * am * u * u, q = am * u, r = -am;
            } else {
              p = D, q = 0, r = 0;
            }
            x = x0 + s * p, v = s * q, a = s * r;
          }};
}

Segment dwell(double t0, double x0, double T) {
  return {t0, t0 + T, [=](double, double& x, double& v, double& a) { x = x0, v = 0, a = 0; }};
}

// x0 + A (1 - cos(2 pi f t)) / 2 over whole periods: starts and ends at rest.
Segment cosine(double t0, double x0, double A, double f, int periods) {
  const double w = 2 * kPi * f;
  return {t0, t0 + periods / f, [=](double t, double& x, double& v, double& a) {
            x = x0 + 0.5 * A * (1 - std::cos(w * t)), v = 0.5 * A * w * std::sin(w * t),
            a = 0.5 * A * w * w * std::cos(w * t);
          }};
}

struct Reference {
  std::vector<Segment> seg;
  void at(double t, double& x, double& v, double& a) const {
    auto it = std::upper_bound(seg.begin(), seg.end(), t, [](double tt, const Segment& s) { return tt < s.t1; });
    if (it == seg.end()) it = seg.end() - 1;
    it->eval(std::clamp(t - it->t0, 0.0, it->t1 - it->t0), x, v, a);
  }
};

Reference make_reference(Rng& r, double duration, double travel) {
  Reference ref;
  double t = 0.0, x = 0.0;
  const auto end_of = [](const Segment& s) {
    double xe, ve, ae;
    s.eval(s.t1 - s.t0, xe, ve, ae);
    return xe;
  };
  const auto push = [&](Segment s) {
    x = end_of(s);
    t = s.t1;
    ref.seg.push_back(std::move(s));
  };
  push(dwell(0.0, 0.0, r.u(0.1, 0.3)));
  bool long_move = true;
  while (t < duration) {
    if (long_move) {  // across most of the travel: ripples, springs and contacts are passed over
      const double target = x < 0.5 * travel ? r.u(0.8, 1.0) * travel : r.u(0.0, 0.2) * travel;
      push(move(t, x, target - x, r.u(0.02, 0.2), r.u(0.5, 5.0)));
    } else {
      const double k = r.u(0.0, 1.0);
      if (k < 0.3) {
        push(dwell(t, x, r.u(0.1, 0.8)));
      } else if (k < 0.55) {  // back-and-forth reversals
        const double d = r.u(0.5e-3, 5e-3) * (x > 0.5 * travel ? -1 : 1);
        const int n = 2 + static_cast<int>(r.u(0, 3));
        for (int i = 0; i < n; ++i) push(move(t, x, (i % 2 ? -d : d), r.u(0.01, 0.08), r.u(0.5, 3.0)));
      } else if (k < 0.8) {  // creeping: 0.05-0.5 mm/s over 0.1-1 mm, reaching speed in 10 ms
        const double vc = r.u(0.05e-3, 0.5e-3), d = std::min(r.u(0.1e-3, 1e-3), vc * 2.0);
        push(move(t, x, d * (x > 0.5 * travel ? -1 : 1), vc, vc / 0.01));
      } else {
        const double A = r.u(2e-3, 20e-3) * (x > 0.5 * travel ? -1 : 1);
        push(cosine(t, x, A, r.u(0.5, 3.0), 1 + static_cast<int>(r.u(0, 2))));
      }
    }
    long_move = !long_move;
  }
  return ref;
}

// One direction only: forward moves (trapezoids), creeping and dwells from 0 to `travel`, paced to
// end near the record's end, never reversing.
Reference make_forward_reference(Rng& r, double duration, double travel) {
  Reference ref;
  double t = 0.0, x = 0.0;
  const int moves = 6 + static_cast<int>(r.u(0, 7));
  std::vector<double> share(static_cast<std::size_t>(moves));
  double sum = 0.0;
  for (double& s : share) sum += (s = r.u(0.3, 1.0));
  const double v_need = travel / (0.6 * duration);
  ref.seg.push_back(dwell(0.0, 0.0, r.u(0.1, 0.3)));
  t = ref.seg.back().t1;
  for (int i = 0; i < moves; ++i) {
    const double d = travel * share[static_cast<std::size_t>(i)] / sum;
    const double vm = std::max(v_need, r.u(0.005, 0.05)) * (r.coin(0.2) ? 0.05 : 1.0);  // some creeping
    ref.seg.push_back(move(t, x, d, vm, r.u(0.5, 3.0)));
    x += d;
    t = ref.seg.back().t1;
    ref.seg.push_back(dwell(t, x, r.u(0.05, 0.4)));
    t = ref.seg.back().t1;
  }
  if (t < duration) ref.seg.push_back(dwell(t, x, duration - t + 1.0));
  return ref;
}

// ---- the drive ---------------------------------------------------------------------------------
struct Truth {
  double m{80.0};
  // base friction (known to the model), truth form
  bool base_static{false};
  double Fc{0}, Fs{0}, vs{1e-3}, s2{0};
  // form deviations
  double vt{1e-5}, asym{0.0}, delta{2.0};
  // hidden effects
  double F0{0};  // constant
  double hc{0};  // coulomb
  double hv{0};  // viscous
  bool strib{false};
  double sFs{0}, sFc{0}, svs{1e-3};  // stribeck
  bool pres{false};
  double sig0{0}, sig1{0};                        // presliding
  double cp{0}, ca{0}, cphi{0}, cb{0}, cphi3{0};  // cogging
  double rp{0}, rA{0}, rphi{0};                   // reluctance
  bool grind{false};
  double C{0}, ke{0}, xc{0};  // grinding
  double k{0}, xr{0};         // spring
  double delay{0};            // input delay
};

double sgn_t(const Truth& T, double v) { return v / std::sqrt(v * v + T.vt * T.vt); }
double asym(const Truth& T, double v) { return 1.0 + (v > 0 ? T.asym : v < 0 ? -T.asym : 0.0); }
double stribeck_level(double Fc, double Fs, double vs, double delta, double v) {
  return Fc + (Fs - Fc) * std::exp(-std::pow(std::abs(v / vs), delta));
}

// State y = {x, v, z, fg}; derivative under acting thrust F.
struct Deriv {
  double dx, dv, dz, dfg;
};
Deriv derivative(const Truth& T, const double y[4], double F) {
  const double x = y[0], v = y[1], z = y[2], fg = y[3];
  double friction = 0.0, dz = 0.0;
  if (T.pres) {  // LuGre-type bristles on the base friction levels
    const double g = stribeck_level(T.Fc, T.Fs, T.vs, T.delta, v) * asym(T, v);
    dz = v - T.sig0 * std::abs(v) * z / g;
    friction = T.sig0 * z + T.sig1 * dz + T.s2 * v;
  } else if (T.base_static) {
    friction = stribeck_level(T.Fc, T.Fs, T.vs, T.delta, v) * sgn_t(T, v) * asym(T, v) + T.s2 * v;
  }
  double hidden = T.F0 + T.hc * sgn_t(T, v) * asym(T, v) + T.hv * v + T.k * (x - T.xr);
  if (T.strib) hidden += stribeck_level(T.sFc, T.sFs, T.svs, T.delta, v) * sgn_t(T, v) * asym(T, v);
  if (T.cp > 0) hidden += T.ca * std::sin(2 * kPi * x / T.cp + T.cphi) + T.cb * std::sin(6 * kPi * x / T.cp + T.cphi3);
  if (T.rp > 0) hidden += F * T.rA * std::sin(2 * kPi * x / T.rp + T.rphi);
  double dfg = 0.0;
  if (T.grind) {
    const bool contact = x > T.xc;
    dfg = (contact ? T.ke * v : 0.0) - (T.ke / T.C) * fg;
    if (contact) hidden += fg;
  }
  return {v, (F - friction - hidden) / T.m, dz, dfg};
}

// Fastest decay rate of the internal states (for the RK4 step size).
// Bristles: dz/dt decays at sigma0 |v| / g(v) (g >= 0.9 Fc here), and the bristle spring and
// damper act on the mass at sigma1/m. A Coulomb-type term L v/sqrt(v^2 + vt^2) has the slope L/vt
// at v = 0, a decay rate L/(vt m) of the velocity. Grinding: ke/C.
double stiffness(const Truth& T, double v) {
  double r = 0.0;
  if (T.pres) r = std::max({r, T.sig0 * std::max(std::abs(v), 1e-3) / (0.9 * T.Fc), T.sig1 / T.m});
  const double coulomb = (T.base_static && !T.pres ? T.Fs : 0.0) + T.hc + (T.strib ? T.sFs : 0.0);
  if (coulomb > 0) r = std::max(r, 1.03 * coulomb / (T.vt * T.m));
  if (T.grind) r = std::max(r, T.ke / T.C);
  return r;
}

void rk4(const Truth& T, double y[4], double F, double h) {
  double k[4][4], tmp[4];
  const auto d = [&](const double* s, double* out) {
    const Deriv q = derivative(T, s, F);
    out[0] = q.dx, out[1] = q.dv, out[2] = q.dz, out[3] = q.dfg;
  };
  d(y, k[0]);
  for (int i = 0; i < 4; ++i) tmp[i] = y[i] + 0.5 * h * k[0][i];
  d(tmp, k[1]);
  for (int i = 0; i < 4; ++i) tmp[i] = y[i] + 0.5 * h * k[1][i];
  d(tmp, k[2]);
  for (int i = 0; i < 4; ++i) tmp[i] = y[i] + h * k[2][i];
  d(tmp, k[3]);
  for (int i = 0; i < 4; ++i) y[i] += h / 6.0 * (k[0][i] + 2 * k[1][i] + 2 * k[2][i] + k[3][i]);
}

// Integrates over [t0, t1] with the thrust held at F: at least `min_sub` RK4 steps, more where
// the internal states are stiff (h * rate <= 1).
void advance(const Truth& T, double y[4], double F, double t0, double t1, int min_sub) {
  const double H = t1 - t0;
  if (!(H > 0)) return;
  const int n = std::min(20000, std::max(min_sub, static_cast<int>(std::ceil(H * stiffness(T, y[1]) / 1.0))));
  for (int i = 0; i < n; ++i) rk4(T, y, F, H / n);
}

std::string num(double v) {
  char b[64];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

}  // namespace

const std::vector<std::string>& vocabulary() {
  static const std::vector<std::string> v{
      "constant_force",    "coulomb_friction", "viscous_friction", "stribeck_friction", "presliding", "cogging_ripple",
      "reluctance_ripple", "grinding_force",   "spring_force",     "mass_error",        "input_delay"};
  return v;
}

std::string Generated::csv() const {
  std::string out = "t,x,force_N,xd\n";
  char b[128];
  for (std::size_t k = 0; k < t.size(); ++k) {
    std::snprintf(b, sizeof b, "%.17g,%.17g,%.17g,%.17g\n", t[k], x[k], force_N[k], xd[k]);
    out += b;
  }
  return out;
}

namespace {

// Whether `name` is one of the spec's hidden effects.
bool has_hidden(const CaseSpec& spec, const char* name) {
  return std::find(spec.hidden.begin(), spec.hidden.end(), name) != spec.hidden.end();
}

// The known drive: base friction (static, with probability 1/2, always under presliding) and,
// with form_deviation, the friction forms that differ from the model's. Three draws either way.
void draw_base_friction(const CaseSpec& spec, Rng& r, Truth& T) {
  T.base_static = has_hidden(spec, "presliding") || r.coin(0.5);
  if (T.base_static) {
    T.Fc = r.u(10, 30), T.Fs = T.Fc * r.u(1.1, 1.5), T.vs = r.u(1e-3, 5e-3), T.s2 = r.u(20, 150);
  }
  if (spec.form_deviation) {
    T.vt = r.u(20e-6, 300e-6), T.asym = r.u(-0.02, 0.02), T.delta = 2.0 + r.u(-0.3, 0.3);
  } else {
    r.u(0, 1), r.u(0, 1), r.u(0, 1);  // the same draws follow either way
  }
}

// The hidden effects of the spec, drawn in the vocabulary's order into T, each also into `truth`
// in the vocabulary's parametrisation. `m_nom`: the nominal mass, `travel`: the reference's.
void draw_hidden(const CaseSpec& spec, Rng& r, double m_nom, double travel, Truth& T, std::vector<Effect>& truth) {
  const auto hidden = [&](const char* n) { return has_hidden(spec, n); };
  const double v_typ = 0.05;  // m/s, a typical move speed of the reference
  if (hidden("constant_force")) {
    T.F0 = r.sign() * r.u(3, 20);
    truth.push_back({"constant_force", {{"force", T.F0}}});
  }
  if (hidden("coulomb_friction")) {
    T.hc = r.u(5, 30);
    truth.push_back({"coulomb_friction", {{"coulomb_force", T.hc}}});
  }
  if (hidden("viscous_friction")) {
    T.hv = r.u(50, 300);
    truth.push_back({"viscous_friction", {{"viscous", T.hv}}});
  }
  if (hidden("stribeck_friction")) {
    T.strib = true;
    T.sFc = r.u(5, 20), T.sFs = T.sFc + r.u(5, 20), T.svs = r.u(1e-3, 10e-3);
    truth.push_back(
        {"stribeck_friction", {{"static_force", T.sFs}, {"coulomb_force", T.sFc}, {"stribeck_velocity", T.svs}}});
  }
  if (hidden("presliding")) {
    T.pres = true;
    T.sig0 = std::exp(r.u(std::log(1e5), std::log(1e7)));
    T.sig1 = 2 * r.u(0.05, 0.5) * std::sqrt(T.sig0 * T.m);
    truth.push_back({"presliding", {{"bristle_stiffness", T.sig0}, {"bristle_damping", T.sig1}}});
  }
  if (hidden("cogging_ripple")) {
    T.cp = r.u(0.01, std::min(0.04, travel / 3)), T.ca = r.u(2, 10), T.cphi = r.u(-kPi, kPi);
    if (spec.ripple_periods > 0) T.cp = travel / spec.ripple_periods;
    T.cb = T.ca * r.u(0, 0.4), T.cphi3 = r.u(-kPi, kPi);
    truth.push_back({"cogging_ripple",
                     {{"pitch", T.cp},
                      {"cogging_amplitude", T.ca},
                      {"cogging_phase", T.cphi},
                      {"cogging_third", T.cb},
                      {"cogging_third_phase", T.cphi3}}});
  }
  if (hidden("reluctance_ripple")) {
    T.rp = r.u(0.01, std::min(0.04, travel / 3)), T.rA = r.u(0.03, 0.08), T.rphi = r.u(-kPi, kPi);
    if (spec.ripple_periods > 0) T.rp = travel / spec.ripple_periods;
    truth.push_back(
        {"reluctance_ripple", {{"pitch", T.rp}, {"reluctance_amplitude", T.rA}, {"reluctance_phase", T.rphi}}});
  }
  if (hidden("grinding_force")) {
    T.grind = true;
    T.xc = r.u(0.2, 0.8) * travel;
    T.C = r.u(20, 100) / v_typ;
    T.ke = T.C / r.u(2e-3, 50e-3);
    truth.push_back({"grinding_force", {{"damping", T.C}, {"stiffness", T.ke}, {"contact_position", T.xc}}});
  }
  if (hidden("spring_force")) {
    T.k = r.u(200, 2000), T.xr = r.u(0.0, 1.0) * travel;
    truth.push_back({"spring_force", {{"stiffness", T.k}, {"rest_position", T.xr}}});
  }
  if (hidden("mass_error")) {
    T.m = m_nom * (1.0 + r.sign() * r.u(0.1, 0.3));
    truth.push_back({"mass_error", {{"mass", T.m}}});
  }
  if (hidden("input_delay")) {
    T.delay = r.u(0.5e-3, 3e-3);
    truth.push_back({"input_delay", {{"delay", T.delay}}});
  }
}

constexpr double kForceMax = 1500.0;  // [N] the controller's saturation

// The controller and sensor drawn for a record, and the controller's state.
struct Loop {
  bool pid{false}, ff{false};
  int cmd_delay{0};  // samples of computation delay (0 or 1)
  double bw{0.0};    // [Hz] bandwidth
  double w{0.0}, wv{0.0}, wp{0.0}, tf{0.0};
  double q{0.0}, noise{0.0}, jitter{0.0};  // [m] quantization, [m] noise, [s] sample jitter
  double m_nom{0.0};
  // state
  double integ{0.0}, e_prev{0.0}, d_filt{0.0}, x_prev{0.0}, v_filt{0.0};
  double pending{0.0};  // computed, waiting one sample
};

// Draws the controller (PID or cascade, feed-forward, delay, bandwidth) and the sensor.
Loop draw_loop(const CaseSpec& spec, Rng& r, double m_nom, double Ts) {
  Loop L;
  L.m_nom = m_nom;
  L.pid = r.coin(0.5);
  L.ff = r.coin(0.5);
  L.cmd_delay = r.coin(0.3) ? 1 : 0;
  // Bandwidths a 1 kHz loop with a differenced velocity holds without a limit cycle: the PID's
  // triple pole at 15-40 Hz; the cascade's velocity loop at 30-60 Hz (with the one-sample
  // delay: 0.4 and 0.6 of these), its position loop at a quarter of that.
  L.bw = (L.pid ? r.u(15, 40) : r.u(30, 60) / 4.0) * (L.cmd_delay ? (L.pid ? 0.4 : 0.6) : 1.0);
  if (spec.bandwidth_hz > 0) L.bw = spec.bandwidth_hz;
  L.w = 2 * kPi * L.bw;
  L.wv = 4 * L.w, L.wp = L.w;
  L.q = r.u(50e-9, 200e-9), L.noise = r.u(0.0, 20e-9);
  L.jitter = 0.02 * Ts;
  L.tf = 1.0 / (5.0 * L.w);  // derivative / velocity filter time constant
  return L;
}

// The controller's thrust at a sample (k: its index, dt: since the previous one) for the
// measured position xm and the reference xd, vd, ad, saturated at +-kForceMax with anti-windup.
// PID: triple pole at -w: Kp = 3 m w^2, Ki = m w^3, Kd = 3 m w. Cascade: PI velocity loop at wv
// (integral corner wv/4) around a P position loop at wv/4.
double control(Loop& L, long k, double dt, double xm, double xd, double vd, double ad) {
  const double e = xd - xm;
  double F;
  if (L.pid) {
    const double de = k > 0 ? (e - L.e_prev) / dt : 0.0;
    L.d_filt += (de - L.d_filt) * dt / (L.tf + dt);
    F = L.m_nom * (3 * L.w * L.w * e + 3 * L.w * L.d_filt + L.w * L.w * L.w * L.integ) + (L.ff ? L.m_nom * ad : 0.0);
    const double Fs = std::clamp(F, -kForceMax, kForceMax);
    if (Fs == F || (F > kForceMax) != (e > 0)) L.integ += e * dt;  // anti-windup: no integration into saturation
    F = Fs;
  } else {
    const double vm = k > 0 ? (xm - L.x_prev) / dt : 0.0;
    L.v_filt += (vm - L.v_filt) * dt / (L.tf + dt);
    const double ev = L.wp * e + vd - L.v_filt;
    F = L.m_nom * L.wv * (ev + 0.25 * L.wv * L.integ) + (L.ff ? L.m_nom * ad : 0.0);
    const double Fs = std::clamp(F, -kForceMax, kForceMax);
    if (Fs == F || (F > kForceMax) != (ev > 0)) L.integ += ev * dt;
    F = Fs;
  }
  L.e_prev = e;
  L.x_prev = xm;
  if (!L.cmd_delay) return F;
  const double act = L.pending;
  L.pending = F;
  return act;
}

// Integrates the drive from sample k to k+1: the thrust acting at t is the one applied at
// t - delay, so the interval is cut where a delayed thrust switches.
void integrate_sample(const Truth& T, double y[4], const std::vector<double>& t_true,
                      const std::vector<double>& applied, long k) {
  const double tk = t_true[k];
  const double t1 = t_true[k + 1];
  std::vector<double> cuts{tk};
  for (long j = std::max(0L, k - 10); j <= k + 1; ++j) {
    const double s = t_true[j] + T.delay;
    if (T.delay > 0 && s > tk && s < t1) cuts.push_back(s);
  }
  cuts.push_back(t1);
  std::sort(cuts.begin(), cuts.end());
  for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
    const double mid = 0.5 * (cuts[c] + cuts[c + 1]) - T.delay;
    double Fa = 0.0;
    if (mid >= 0.0) {
      const long j = std::upper_bound(t_true.begin(), t_true.begin() + k + 1, mid) - t_true.begin() - 1;
      Fa = applied[static_cast<std::size_t>(std::max(0L, j))];
    }
    advance(T, y, Fa, cuts[c], cuts[c + 1], 10);
  }
}

// The closed loop over N samples at period Ts (jittered instants): each sample's stamp (with its
// stamp error), quantized noisy position, applied thrust and reference go to `out`.
void simulate(const Truth& T, Loop& L, const Reference& ref, Rng& r, long N, double Ts, Generated& out) {
  std::vector<double> t_true(static_cast<std::size_t>(N));
  for (long k = 0; k < N; ++k) t_true[k] = k * Ts + (k > 0 && k + 1 < N ? r.u(-L.jitter, L.jitter) : 0.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  double y[4] = {0.0, 0.0, 0.0, 0.0};
  std::vector<double> applied(static_cast<std::size_t>(N), 0.0);
  for (long k = 0; k < N; ++k) {
    const double tk = t_true[k];
    const double dt = k > 0 ? tk - t_true[k - 1] : Ts;
    double xd, vd, ad;
    ref.at(tk, xd, vd, ad);
    const double xm = L.q * std::round((y[0] + L.noise * gauss(r.g)) / L.q);
    const double act = control(L, k, dt, xm, xd, vd, ad);
    applied[k] = act;
    out.t.push_back(tk + (k > 0 && k + 1 < N ? r.u(-kStampError, kStampError) : 0.0));
    out.x.push_back(xm);
    out.force_N.push_back(act);
    out.xd.push_back(xd);
    if (k + 1 == N) break;
    integrate_sample(T, y, t_true, applied, k);
    if (!std::isfinite(y[0]) || !std::isfinite(y[1])) throw std::runtime_error("drivegen: the simulation diverged");
  }
}

// The model the fit starts from: the known drive (nominal mass, base friction, the encoder),
// no hidden effect.
std::string scenario_yaml(const CaseSpec& spec, double Ts, double m_nom, const Truth& T, const Loop& L, bool grinding) {
  std::ostringstream yaml;
  yaml << "name: drivegen_" << spec.seed << "\nduration: " << num(spec.duration) << "\ncontrol_period: " << num(Ts)
       << "\nplant:\n  mass: " << num(m_nom) << "\n";
  if (T.base_static)
    yaml << "  friction: {model: static, static_force: " << num(T.Fs) << ", coulomb_force: " << num(T.Fc)
         << ", stribeck_velocity: " << num(T.vs) << ", stribeck_exponent: 2, viscous: " << num(T.s2) << "}\n";
  else yaml << "  friction: {model: none}\n";
  if (grinding) yaml << "  grinding: {enabled: false}\n";
  // the encoder is known to its engineer: the fit's noise floor comes from it
  yaml << "  sensor: {quantization: " << num(L.q) << ", noise_stddev: " << num(L.noise) << "}\n";
  yaml << "controller: {type: cascade}\nreference: {type: step}\n";
  return yaml.str();
}

// Everything else that was drawn (Generated::knobs) and the one-line description.
void describe(const CaseSpec& spec, double m_nom, double travel, const Truth& T, const Loop& L, Generated& out) {
  const long N = static_cast<long>(out.force_N.size());
  long saturated = 0;
  for (double f : out.force_N) saturated += std::abs(f) >= kForceMax ? 1 : 0;
  out.knobs = {{"saturated_fraction", static_cast<double>(saturated) / static_cast<double>(N)},
               {"mass_nominal_kg", m_nom},
               {"travel_m", travel},
               {"controller", L.pid ? 0.0 : 1.0},
               {"bandwidth_hz", L.bw},
               {"feedforward", L.ff ? 1.0 : 0.0},
               {"command_delay_samples", L.cmd_delay},
               {"quantization_m", L.q},
               {"noise_m", L.noise},
               {"jitter_s", L.jitter},
               {"stamp_error_s", kStampError / std::sqrt(3.0)},
               {"coulomb_transition_mps", T.vt},
               {"asymmetry", T.asym},
               {"stribeck_exponent", T.delta},
               {"base_static_friction", T.base_static ? 1.0 : 0.0}};
  char b[512];
  std::snprintf(b, sizeof b,
                "%s: m=%.1f kg %s %.0f Hz%s%s, q=%.0f nm, travel %.0f mm%s, %s friction, vt=%.0f um/s, asym %.3f, %.1f "
                "%% saturated",
                spec.category.c_str(), m_nom, L.pid ? "PID" : "cascade", L.bw, L.ff ? " +ff" : "",
                L.cmd_delay ? " +1-sample delay" : "", L.q * 1e9, travel * 1e3,
                spec.one_direction ? " one direction" : "", T.base_static ? "static" : "no", T.vt * 1e6, T.asym,
                100.0 * static_cast<double>(saturated) / static_cast<double>(N));
  out.description = b;
}

}  // namespace

Generated generate(const CaseSpec& spec) {
  for (const auto& h : spec.hidden)
    if (std::find(vocabulary().begin(), vocabulary().end(), h) == vocabulary().end())
      throw std::invalid_argument("drivegen: unknown effect '" + h + "'");
  Rng r{std::mt19937_64(spec.seed * 0x9E3779B97F4A7C15ULL + 12345)};
  Generated out;
  Truth T;
  const double m_nom = r.u(40.0, 120.0);
  T.m = m_nom;
  // position-dependent effects need travel: at least three ripple pitches, a contact passed often
  const bool positional = has_hidden(spec, "cogging_ripple") || has_hidden(spec, "reluctance_ripple") ||
                          has_hidden(spec, "spring_force") || has_hidden(spec, "grinding_force");
  const double travel = positional ? r.u(0.06, 0.15) : r.u(0.02, 0.15);
  const double Ts = 1.0 / spec.sample_rate;
  draw_base_friction(spec, r, T);
  draw_hidden(spec, r, m_nom, travel, T, out.truth);
  Loop L = draw_loop(spec, r, m_nom, Ts);
  const Reference ref =
      spec.one_direction ? make_forward_reference(r, spec.duration, travel) : make_reference(r, spec.duration, travel);
  const long N = static_cast<long>(std::lround(spec.duration * spec.sample_rate)) + 1;
  simulate(T, L, ref, r, N, Ts, out);
  out.scenario_yaml = scenario_yaml(spec, Ts, m_nom, T, L, spec.grinding_process || has_hidden(spec, "grinding_force"));
  describe(spec, m_nom, travel, T, L, out);
  return out;
}

std::pair<double, double> integrate_mass(double m, double F, double c, double v0, double duration, int steps) {
  Truth T;
  T.m = m;
  T.hv = c;
  double y[4] = {0.0, v0, 0.0, 0.0};
  for (int i = 0; i < steps; ++i) rk4(T, y, F, duration / steps);
  return {y[0], y[1]};
}

std::vector<CaseSpec> issue20_cases(int n, std::uint64_t seed) {
  const int special = n - static_cast<int>(std::lround(0.55 * n));
  std::vector<CaseSpec> out = standard_cases(n - special, seed);
  Rng r{std::mt19937_64(seed * 6151 + 7)};
  for (std::size_t i = 0; i < out.size(); ++i)
    if (i % 3 == 2) {
      out[i].bandwidth_hz = r.u(4.0, 14.0);
      out[i].category = "standard, 4-14 Hz loop";
    }
  const int short_n = static_cast<int>(std::lround(special * 15.0 / 45.0));
  const int asym_n = static_cast<int>(std::lround(special * 10.0 / 45.0));
  const int one_n = static_cast<int>(std::lround(special * 10.0 / 45.0));
  const int mass_n = special - short_n - asym_n - one_n;
  const auto add = [&](std::vector<std::string> hidden, const char* category) {
    CaseSpec c;
    c.hidden = std::move(hidden);
    c.category = category;
    if (r.coin(0.3)) c.bandwidth_hz = r.u(4.0, 14.0);
    out.push_back(c);
    return &out.back();
  };
  for (int i = 0; i < short_n; ++i) {
    std::vector<std::string> h{r.coin(0.6) ? "cogging_ripple" : "reluctance_ripple"};
    if (r.coin(0.4)) h.push_back("viscous_friction");
    add(h, "short travel ripple")->ripple_periods = r.u(1.5, 3.0);
  }
  for (int i = 0; i < asym_n; ++i) add({"coulomb_friction", "constant_force"}, "asymmetric friction");
  for (int i = 0; i < one_n; ++i) {
    std::vector<std::string> h{r.coin(0.5) ? "coulomb_friction" : "constant_force"};
    if (r.coin(0.3)) h.push_back("viscous_friction");
    add(h, "one direction")->one_direction = true;
  }
  for (int i = 0; i < mass_n; ++i) add({"mass_error", "cogging_ripple"}, "mass error + ripple");
  for (std::size_t i = 0; i < out.size(); ++i) out[i].seed = seed * 2000003ULL + i;
  return out;
}

std::vector<CaseSpec> standard_cases(int n, std::uint64_t seed) {
  Rng r{std::mt19937_64(seed * 7919 + 1)};
  std::vector<CaseSpec> out;
  const auto& v = vocabulary();
  const int free_n = std::max(1, static_cast<int>(std::lround(0.12 * n)));
  const int per = std::max(1, n / 20);
  for (int i = 0; i < free_n; ++i) out.push_back({});
  for (int k = 0; k < per; ++k)
    for (const auto& e : v) out.push_back({0, {e}});
  while (static_cast<int>(out.size()) < n) {
    const std::string a = v[static_cast<std::size_t>(r.u(0, v.size()))],
                      b = v[static_cast<std::size_t>(r.u(0, v.size()))];
    if (a == b) continue;
    const std::set<std::string> p{a, b};
    if (p.count("coulomb_friction") && p.count("stribeck_friction")) continue;
    out.push_back({0, {a, b}});
  }
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i].seed = seed * 1000003ULL + i;
    const auto& h = out[i].hidden;
    out[i].grinding_process = std::find(h.begin(), h.end(), "grinding_force") != h.end();
  }
  return out;
}

namespace {

// The whole of `text` as a number > 0 (or >= 0 with zero_ok), finite.
double checked_number(const std::string& name, const std::string& text, bool zero_ok) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v))
    throw std::invalid_argument(name + " = '" + text + "': not a number");
  if (v < 0.0 || (v == 0.0 && !zero_ok))
    throw std::invalid_argument(name + " = '" + text + "': must be " + (zero_ok ? ">= 0" : "> 0"));
  return v;
}

}  // namespace

CaseSpec parse_command_line(const std::vector<std::string>& args) {
  if (args.size() < 2) throw std::invalid_argument("expected at least SEED DIR");
  CaseSpec spec;
  const std::string& seed = args[0];
  char* end = nullptr;
  errno = 0;
  spec.seed = std::strtoull(seed.c_str(), &end, 10);
  if (seed.empty() || !std::isdigit(static_cast<unsigned char>(seed[0])) || *end != '\0' || errno == ERANGE)
    throw std::invalid_argument("SEED = '" + seed + "': not a non-negative integer");
  if (args.size() > 2) spec.duration = checked_number("DURATION_S", args[2], false);
  if (args.size() > 3) {
    std::stringstream ss(args[3]);
    std::string e;
    while (std::getline(ss, e, ','))
      if (!e.empty() && e != "none") spec.hidden.push_back(e);
  }
  for (std::size_t a = 4; a < args.size(); ++a) {
    const std::string& w = args[a];
    if (w == "grinding") spec.grinding_process = true;
    else if (w == "noform")
      spec.form_deviation = false;  // the model's friction form: no transition, asymmetry or exponent change
    else if (w == "onedir") spec.one_direction = true;
    else if (w.rfind("periods=", 0) == 0) spec.ripple_periods = checked_number("periods", w.substr(8), true);
    else if (w.rfind("bw=", 0) == 0) spec.bandwidth_hz = checked_number("bw", w.substr(3), true);
    else throw std::invalid_argument("'" + w + "': expected one of grinding, noform, onedir, periods=P, bw=HZ");
  }
  return spec;
}

}  // namespace fdgen
