#include "feeddrive/fit/verdict.hpp"
#include "text.hpp"

#include "feeddrive/fit/replay.hpp"
#include "feeddrive/plant/effects.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

namespace feeddrive::fit {
using text::fmt;
using text::par;
namespace {

// The sensor's part of the floor (header): q and sigma_n from plant.sensor, or without one q the
// record's smallest position step and sigma_n = 0; sigma_x = sqrt(sigma_n^2 + q^2/12); the source line.
NoiseFloor sensor_floor(const MeasuredData& d, const plant::PlantParams& model, double stamp_error) {
  NoiseFloor f;
  f.quantization = model.sensor.quantization;
  f.noise = model.sensor.noise_stddev;
  f.stamp_error = stamp_error;
  if (model.sensor.ideal()) {
    f.from_scenario = false;
    f.quantization = smallest_position_step(d);
    f.source =
        fmt("the scenario gives no sensor (plant.sensor): q = %.3g nm is the record's smallest position step, "
            "noise unknown (taken as 0): give plant.sensor for a floor you can trust",
            f.quantization * 1e9);
  } else {
    f.source = fmt("plant.sensor: quantization %.3g nm, noise %.3g nm", f.quantization * 1e9, f.noise * 1e9);
  }
  f.source += f.stamp_error > 0 ? fmt("; time stamps: %.3g us (1 sigma)", f.stamp_error * 1e6)
                                : std::string("; time-stamp error not given (--time-stamp-error): taken as 0");
  f.position = std::sqrt(f.noise * f.noise + f.quantization * f.quantization / 12.0);
  return f;
}

// What each sample carries (header): its position variance s_k^2 = sigma_x^2 + v_k^2 sigma_t^2,
// and the thrust's jump dF_k = F_k - F_k-1 there (the thrust held over [t_k, t_k+1); 0 without a
// stamp error); with the mass and sigma_t^2 that scale them.
struct SampleErrors {
  std::vector<double> var_x, dF;
  double mass{0.0}, st2{0.0};
};
SampleErrors sample_errors(const Record& rec, const plant::PlantParams& model, const NoiseFloor& f) {
  const long n = static_cast<long>(rec.data->t.size());
  SampleErrors s;
  s.mass = plant::effective_params(model).mass;
  s.st2 = f.stamp_error * f.stamp_error;
  s.var_x.assign(static_cast<std::size_t>(n), f.position * f.position);
  s.dF.assign(static_cast<std::size_t>(n), 0.0);
  if (s.st2 > 0) {
    const double gain = thrust_per_input(rec, model);
    for (long k = 0; k < n; ++k) s.var_x[static_cast<std::size_t>(k)] += rec.motion.v[k] * rec.motion.v[k] * s.st2;
    for (long k = 1; k + 1 < n; ++k) s.dF[static_cast<std::size_t>(k)] = gain * (rec.input[k] - rec.input[k - 1]);
  }
  return s;
}

// Adds to `sum`, for each thrust jump inside the replay window [s, e], the squared drift of a
// thrust switched sigma_t early or late (header): sigma_t^2 (dF_k/m)^2 ||P ramp_k||^2, ramp_k =
// max(0, t - t_k) over the window's samples, P the projection off its least-squares line span{1, t}.
void add_stamp_drift(const std::vector<double>& t, long s, long e, const SampleErrors& se, double& sum) {
  std::vector<double> tau(static_cast<std::size_t>(e - s + 1), 0.0);
  double S0 = 0, S1 = 0, S2 = 0;
  for (long l = s; l <= e; ++l) {
    const double x = t[l] - t[s];
    tau[static_cast<std::size_t>(l - s)] = x;
    S0 += 1;
    S1 += x;
    S2 += x * x;
  }
  const double det = S0 * S2 - S1 * S1;
  for (long k = s + 1; k < e; ++k) {
    const double g = se.dF[static_cast<std::size_t>(k)];
    if (g == 0.0 || !(det > 0)) continue;
    const double tk = t[k] - t[s];
    double E0 = 0, E1 = 0;
    for (const double x : tau) {
      const double y = std::max(0.0, x - tk);
      E0 += y;
      E1 += y * x;
    }
    const double a = (S2 * E0 - S1 * E1) / det, b = (S0 * E1 - S1 * E0) / det;
    double ss = 0.0;
    for (std::size_t l = 1; l < tau.size(); ++l) {
      const double y = std::max(0.0, tau[l] - tk) - a - b * tau[l];
      ss += y * y;
    }
    sum += se.st2 * g * g / (se.mass * se.mass) * ss;
  }
}

// The gap floor (header): over the replay's windows of length W (replay.hpp), the RMS of each
// sample's sensor noise and stamp error, plus the drift of a thrust switched early or late less
// the window's start correction (add_stamp_drift); sigma_x for a record with no window.
double gap_floor(const Record& rec, const SampleErrors& se, double replay_window, double position) {
  const auto& t = rec.data->t;
  const long n = static_cast<long>(t.size());
  const double W = window_length(rec, replay_window);
  double sum = 0.0;
  long count = 0;
  long s = 0;
  while (s + 1 < n) {
    long e = s;
    while (e + 1 < n && t[e + 1] - t[s] <= W + 1e-12) ++e;
    if (e == s) e = s + 1;
    for (long k = s + 1; k <= e; ++k) sum += se.var_x[static_cast<std::size_t>(k)];
    count += e - s;
    if (se.st2 > 0) add_stamp_drift(t, s, e, se, sum);
    s = e;
  }
  return count ? std::sqrt(sum / static_cast<double>(count)) : position;
}

// At filter point tau with half-width L (header): {noise, b} with noise = m^2 sum_k c_k^2 s_k^2
// + sigma_t^2 sum_k (h(tau - t_k) dF_k)^2, the variance of the filtered force residual from the
// sensor and the stamps, and b = sum_j a_j h''(tau - t_mid,j) dt_j^3 / 12, the filter's
// discretisation (b_i = m b).
std::pair<double, double> point_floor(const Record& rec, const SampleErrors& se, double tau, double L) {
  const auto& t = rec.data->t;
  const long n = static_cast<long>(t.size());
  const double mass = se.mass;
  long j0 = static_cast<long>(std::upper_bound(t.begin(), t.end(), tau - L) - t.begin()) - 1;
  j0 = std::max(0L, j0);
  long j1 = std::min(n - 1, static_cast<long>(std::lower_bound(t.begin(), t.end(), tau + L) - t.begin()));
  std::vector<double> c(static_cast<std::size_t>(j1 - j0 + 1), 0.0);
  for (long j = j0; j < j1; ++j) {
    const double g = (kernel(tau - t[j], L) - kernel(tau - t[j + 1], L)) / (t[j + 1] - t[j]);
    c[static_cast<std::size_t>(j + 1 - j0)] += g;
    c[static_cast<std::size_t>(j - j0)] -= g;
  }
  double s = 0.0;
  for (long k = j0; k <= j1; ++k) {
    const double ck = c[static_cast<std::size_t>(k - j0)];
    s += mass * mass * ck * ck * se.var_x[static_cast<std::size_t>(k)];
    if (se.st2 > 0) {
      const double h = kernel(tau - t[k], L) * se.dF[static_cast<std::size_t>(k)];
      s += se.st2 * h * h;
    }
  }
  double b = 0.0;
  for (long j = j0; j < j1; ++j) {
    const double dt = t[j + 1] - t[j], a_mid = 0.5 * (rec.motion.a[j] + rec.motion.a[j + 1]);
    b += a_mid * kernel_dd(tau - 0.5 * (t[j] + t[j + 1]), L) * dt * dt * dt / 12.0;
  }
  return {s, b};
}

// The force floor (header): sensor noise and stamp errors through the filtered acceleration, a
// thrust switched early or late through the filtered thrust, and the filter's discretisation, as
// RMS over the active filter points into f.force_noise, f.force_discretisation and f.force.
void force_floor(const Record& rec, const SampleErrors& se, NoiseFloor& f) {
  const double L = rec.bank.half_width;
  double noise_sum = 0.0, bias_sum = 0.0;
  long count = 0;
  for (std::size_t i = 0; i < rec.bank.tau.size(); ++i) {
    if (i < rec.masked.size() && rec.masked[i]) continue;
    const auto [s, b] = point_floor(rec, se, rec.bank.tau[i], L);
    noise_sum += s;
    bias_sum += se.mass * se.mass * b * b;
    ++count;
  }
  const double nc = std::max(1.0, static_cast<double>(count));
  f.force_noise = count ? std::sqrt(noise_sum / nc) : 0.0;
  f.force_discretisation = count ? std::sqrt(bias_sum / nc) : 0.0;
  f.force = std::sqrt(f.force_noise * f.force_noise + f.force_discretisation * f.force_discretisation);
}

// The record's own scatter at speed (header, "What the record allows"): a sample off the smooth
// motion by an error of standard deviation s_k = sqrt(sigma_x^2 + v_k^2 sigma_t^2) is off the cubic
// through its four neighbours (Lagrange, on the recorded stamps) by e_k = x_k - P_k(t_k), of
// variance (1 + sum_j w_j^2) s_k^2, w_j the cubic's weights (34/36 on equal steps). Over the
// samples at speed (|v| at least half the record's 95th percentile, at least kMinSamples of them:
// there a quantized position is white), the median of e_k^2 / (1 + sum w^2) is 0.455 s^2 for
// Gaussian errors (the median of chi^2 with one degree of freedom) and 0.75 s^2 for a uniform one:
// s^2 = median / 0.455 overstates s by at most 1.3x. A thrust that changes each sample by dF
// leaves the cubic off by about (dF/m) dt^2 / 4 (0.25 nm for 1 N on 100 kg at 1 ms), far below
// any sensor's. {0, 0}: too few samples at speed to say.
struct Scatter {
  double scatter{0.0}, speed{0.0};
};
Scatter scatter_at_speed(const Record& rec) {
  constexpr std::size_t kMinSamples = 50;
  const auto& t = rec.data->t;
  const auto& x = rec.data->x;
  const auto& v = rec.motion.v;
  const std::size_t n = t.size();
  if (n < kMinSamples + 4) return {};
  std::vector<double> speed(v.begin(), v.end());
  for (double& s : speed) s = std::abs(s);
  const double v95 = order_statistic(speed, static_cast<std::size_t>(0.95 * static_cast<double>(n - 1)));
  std::vector<double> e2, at_speed;
  for (std::size_t k = 2; k + 2 < n; ++k) {
    if (!(speed[k] >= 0.5 * v95) || !(v95 > 0)) continue;
    double w2 = 0.0;
    const double e = cubic_gap(t, x, k, &w2);
    e2.push_back(e * e / (1.0 + w2));
    at_speed.push_back(speed[k]);
  }
  if (e2.size() < kMinSamples) return {};
  return {std::sqrt(order_statistic(e2, e2.size() / 2) / 0.455), order_statistic(at_speed, at_speed.size() / 2)};
}

// A stated error at least kRecordMargin times what the record's own scatter allows is taken at
// that bound (header, "What the record allows").
constexpr double kRecordMargin = 3.0;

// plant.sensor's noise sigma_n and quantum q, when sigma_x = sqrt(sigma_n^2 + q^2/12) exceeds
// kRecordMargin times the scatter at speed s: a quantum that alone exceeds it (q^2/12 > (3 s)^2:
// a 5 um encoder claimed for a record in 50 nm steps; issue 20's review found a 0.8 % mass error
// cleared so) is taken as sqrt(12) 3 s, or the record's own smallest step if that is smaller;
// then the noise as sqrt((3 s)^2 - q^2/12) (0 when the quantum alone explains 3 s).
void bound_sensor(const Record& rec, const Scatter& c, NoiseFloor& f) {
  if (!f.from_scenario || !(c.scatter > 0) || !(f.position > kRecordMargin * c.scatter)) return;
  const double allowed = kRecordMargin * c.scatter;
  if (f.quantization * f.quantization / 12.0 > allowed * allowed) {
    f.quantization_given = f.quantization;
    const double step = smallest_position_step(*rec.data);
    f.quantization = std::sqrt(12.0) * allowed;
    if (step > 0) f.quantization = std::min(f.quantization, step);
    f.source += fmt("; quantization taken as %.3g nm: the record's positions at speed scatter by %.3g nm, and its "
                    "smallest step is %.3g nm",
                    f.quantization * 1e9, c.scatter * 1e9, step * 1e9) +
                fmt(", where %.3g nm steps would scatter them by %.3g nm", f.quantization_given * 1e9,
                    f.quantization_given / std::sqrt(12.0) * 1e9);
  }
  const double noise_allowed = std::sqrt(std::max(0.0, allowed * allowed - f.quantization * f.quantization / 12.0));
  if (f.noise > noise_allowed) {
    f.noise_given = f.noise;
    f.noise = noise_allowed;
    f.source +=
        fmt("; noise taken as %.3g nm: the record's positions at speed scatter by %.3g nm about the cubic "
            "through their neighbours, and %.3g nm of noise would make them scatter by more than 3x that",
            f.noise * 1e9, c.scatter * 1e9, f.noise_given * 1e9);
  }
  f.position = std::sqrt(f.noise * f.noise + f.quantization * f.quantization / 12.0);
}

// A --time-stamp-error beyond what the record allows, kRecordMargin max(s, sigma_x) / v (v the
// median speed of the samples at speed): stamps that far off would scatter them at least 3x more
// than they are. Taken at that bound: the floor it would give is larger than the record's own
// scatter, and an all-clear on it false (issue 20's review: 20 us on a record stamped to 1e-15 s
// hid a 1.5 % mass error).
void bound_stamp_error(const Scatter& c, NoiseFloor& f) {
  if (!(f.stamp_error > 0) || !(c.speed > 0)) return;
  const double allowed = kRecordMargin * std::max(c.scatter, f.position) / c.speed;
  if (f.stamp_error <= allowed) return;
  f.stamp_given = f.stamp_error;
  f.stamp_error = allowed;
  f.source += fmt(", taken as %.3g us: the record's positions at speed (median %.3g mm/s) scatter by %.3g nm about "
                  "the cubic through their neighbours",
                  allowed * 1e6, c.speed * 1e3, c.scatter * 1e9) +
              fmt(", and %.3g us would make them scatter by %.3g nm", f.stamp_given * 1e6,
                  std::hypot(f.position, c.speed * f.stamp_given) * 1e9);
}

}  // namespace

NoiseFloor noise_floor(const Record& rec, const plant::PlantParams& model, const FloorOptions& opt) {
  NoiseFloor f = sensor_floor(*rec.data, model, opt.stamp_error);
  const Scatter c = scatter_at_speed(rec);
  bound_sensor(rec, c, f);
  bound_stamp_error(c, f);
  const SampleErrors se = sample_errors(rec, model, f);
  f.gap = gap_floor(rec, se, opt.replay_window, f.position);
  force_floor(rec, se, f);
  f.gap_factor = kGapAllowance;
  f.force_factor = kForceAllowance;
  // the detection limit (header)
  f.window = window_length(rec, opt.replay_window);
  f.half_width = rec.bank.half_width;
  f.limit_gap = f.gap_factor * f.gap * 2.0 * se.mass * std::sqrt(180.0) / (f.window * f.window);
  f.limit_force = f.force_factor * f.force;
  f.limit = std::min(f.limit_gap, f.limit_force);
  return f;
}

std::string within_text(const NoiseFloor& f) {
  return f.gap_factor == f.force_factor
             ? fmt("within = at most %.3gx", f.gap_factor)
             : fmt("within = at most %.3gx (gap) and %.3gx (force)", f.gap_factor, f.force_factor);
}

std::string describe(const NoiseFloor& f) {
  // a stated error the record contradicts, and what was taken (bound_sensor, bound_stamp_error)
  const auto taken = [](const char* what, double given, double used, double scale, const char* unit) {
    return given > 0
               ? std::string("; ") + what + fmt(" %.3g", given * scale) + unit + fmt(" taken as %.3g", used * scale) +
                     unit + ", the most the record's own scatter at speed allows"
               : std::string();
  };
  return fmt("the noise floor (gap %.3g um, force residual %.3g N RMS; ", f.gap * 1e6, f.force) + within_text(f) +
         fmt("; the smallest constant force it shows: %.3g N at W = %.3g s, L = %.3g ms", f.limit, f.window,
             f.half_width * 1e3) +
         taken("plant.sensor's noise", f.noise_given, f.noise, 1e9, " nm") +
         taken("plant.sensor's quantization", f.quantization_given, f.quantization, 1e9, " nm") +
         taken("--time-stamp-error", f.stamp_given, f.stamp_error, 1e6, " us") + ")";
}

bool within_floor(const NoiseFloor& f, double gap, double force_rms) {
  return gap <= f.gap_factor * f.gap && force_rms <= f.force_factor * f.force;
}

const char* verdict_name(Verdict v) {
  switch (v) {
    case Verdict::kExplained: return "explained";
    case Verdict::kNoDiscrepancy: return "no_discrepancy";
    case Verdict::kUnexplained: return "unexplained";
  }
  return "unexplained";
}

namespace {

// what_would_settle for a ripple (cogging_ripple, reluctance_ripple).
std::string settle_ripple(const Envelope& env, const CandidateFit& c, Reason why, double longer) {
  const std::string& n = c.effect.name;
  const double p = par(c.effect, "pitch");
  if (p > 0 && p > env.max_pitch())
    return fmt(
        "a force periodic in position, pitch about %.3g mm, seen over %.2g periods: record a travel of at least 3 "
        "periods (%.3g mm)",
        p * 1e3, env.travel / p, 3 * p * 1e3);
  if (p > 0 && p < env.min_pitch())
    return fmt(
        "a force periodic in position, pitch about %.3g mm (or shorter: not resolved), faster than the filter "
        "resolves at %.3g mm/s: record the moves at most %.3g mm/s (or at a higher sample rate)",
        p * 1e3, env.v_max * 1e3, p / (4.0 * env.filter_half_width) * 1e3);
  if (why == Reason::kPrerequisite)
    return fmt(
        "a force periodic in position cannot be resolved over %.3g mm: record a travel of at least 3 periods of the "
        "pitch you suspect",
        env.travel * 1e3);
  // an amplitude limit no record of motion changes (plausibility.cpp: a thrust modulation below
  // 1 % is what a mass or gain error that small is)
  if (n == "reluctance_ripple" && c.passed_over.find("of the thrust") != std::string::npos)
    return fmt(
        "a thrust that changes with position by less than 1 %% (pitch about %.3g mm): no record of motion tells it "
        "from a mass or gain error that small; measure the thrust at rest at several positions over one pitch (a "
        "force sensor, or the command holding a known load)",
        p * 1e3);
  return fmt(
      "a force periodic in position (pitch about %.3g mm): record more travel over the same range, e.g. a "
      "record of %.3g s with full-travel moves at several speeds",
      p * 1e3, longer);
}

}  // namespace

std::string what_would_settle(const Envelope& env, const CandidateFit& c, Reason why) {
  const std::string& n = c.effect.name;
  const double longer = std::max(2.0 * env.duration, env.duration + 10.0);
  if (is_ripple(n)) return settle_ripple(env, c, why, longer);
  if (why == Reason::kPrerequisite && n == "presliding")
    return "friction at the reversals: record at least 3 reversals or stick phases (short back-and-forth moves)";
  if (why == Reason::kPrerequisite && n == "grinding_force")
    return "a grinding force: describe the grinding process (plant.grinding) or ask for it with --effects "
           "grinding_force";
  if (why == Reason::kPrerequisite) return "";
  // a constant force within the friction's direction asymmetry: moving data cannot tell them apart,
  // whatever the reversals (issue 20's review: "record reversals" for a record with 17 of them)
  if (n == "constant_force" && why == Reason::kImplausible && c.passed_over.find("asymmetry") != std::string::npos)
    return "a constant force or a friction that differs between the directions: only the drive at rest tells them "
           "apart (a constant force pushes at rest, a friction does not): record holds at rest, with the thrust, at "
           "several positions";
  if (n == "coulomb_friction" && why == Reason::kImplausible && c.passed_over.find("form") != std::string::npos)
    return "a change of the friction level within its form: refit the model's friction levels (plant.friction) from "
           "constant-speed moves in both directions, the thrust at each speed";
  if (n == "constant_force" || n == "coulomb_friction")
    return fmt(
        "a force that depends on the direction of motion or not: record moves in both directions (reversals), "
        "%.3g s or more",
        longer);
  if (n == "viscous_friction" || n == "stribeck_friction")
    return fmt(
        "a friction that depends on speed: record moves at several constant speeds (from %.3g to %.3g mm/s), "
        "%.3g s or more",
        0.05 * env.v_max * 1e3, env.v_max * 1e3, longer);
  if (n == "mass_error" && why == Reason::kImplausible && c.effect.parameters.count("mass") &&
      (par(c.effect, "mass") < 0.5 * env.nominal_mass || par(c.effect, "mass") > 2.0 * env.nominal_mass))
    return fmt(
        "a mass %.3g times the nominal: check the units of the position and the input (one off by about that "
        "factor, e.g. inches or cm read as m, looks like this: --units), and the scenario's plant.mass",
        par(c.effect, "mass") / env.nominal_mass);
  if (n == "mass_error" && why == Reason::kImplausible && c.effect.parameters.count("mass") &&
      small_mass_change(env, c.effect))
    return fmt(
        "a mass change of %.2g %%: weigh the moving parts (plant.mass), or record strong accelerations and "
        "decelerations at speed, away from reversals and stops (where friction's form can fake a small mass)",
        100 * (par(c.effect, "mass") - env.nominal_mass) / env.nominal_mass);
  if (n == "mass_error" || n == "input_delay")
    return fmt(
        "a force proportional to the acceleration or a delay: record stronger and faster changes of the thrust "
        "(short accelerations), %.3g s or more",
        longer);
  if (n == "spring_force" || n == "grinding_force")
    return fmt(
        "a force that depends on position: record a longer travel than %.3g mm, passing the range several "
        "times",
        env.travel * 1e3);
  if (n == "presliding") return "friction at the reversals: record more short reversals and stick phases";
  return fmt("record a longer record (%.3g s) with the same moves", longer);
}

std::string what_would_separate(const std::string& a, const std::string& b) {
  const std::set<std::string> p{a, b};
  const auto has = [&](const char* x) { return p.count(x) > 0; };
  if (has("coulomb_friction") && (has("constant_force") || has("stribeck_friction")))
    return "a move in the other direction (a reversal): a Coulomb friction changes sign with the motion, a constant "
           "force does not";
  if (has("viscous_friction") || has("stribeck_friction"))
    return "moves at different speeds: a friction that grows with speed separates from one that does not";
  if (has("spring_force") || has("cogging_ripple") || has("reluctance_ripple") || has("grinding_force"))
    return "a longer travel: forces that depend on position differ over more of it";
  if (has("mass_error") || has("input_delay")) return "different accelerations (short, strong moves and slow ones)";
  return "a record with reversals, a longer travel and moves at different speeds";
}

}  // namespace feeddrive::fit
