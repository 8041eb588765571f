#include "feeddrive/fit/sanity.hpp"
#include "text.hpp"

#include "feeddrive/plant/effects.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace feeddrive::fit {
using text::fmt;
using text::par;
namespace {

// The power of 1000 nearest to r: round(log10(r) / 3).
int thousands(double r) { return static_cast<int>(std::lround(std::log10(r) / 3.0)); }

// a and b (> 0) within 25 % of each other: a measured unit factor that names a unit (a mass error
// or a logger's rate moves it by less); beyond, the factor itself is given (issue 20's review: cm,
// inches and 100 us ticks were snapped to a power of 1000)
bool within_factor(double a, double b) { return std::abs(std::log(a / b)) < std::log(1.25); }

// The SI unit of a role with the prefix of `factor` (a power of 1000: "ks", "km", "GN"), or "".
std::string prefixed_unit(const std::string& role, double factor) {
  const std::string base = role == "t" ? "s" : role == "x" || role == "xd" ? "m" : role == "force" ? "N" : "V";
  const int k = thousands(factor);
  static const char* const prefix[] = {"p", "n", "u", "m", "", "k", "M", "G", "T"};
  if (k < -4 || k > 4 || std::abs(std::log10(factor) - 3.0 * k) > 0.01) return "";
  return prefix[k + 4] + base;
}

// ": likely in UNIT (--units ROLE=UNIT)" for a unit --units names; for one it does not (a time in
// ks, a position in km), the unit and its factor as counts (--units ROLE=counts:FACTOR); "" if the
// factor is no power of 1000.
std::string hint(const std::string& role, double factor) {
  const std::string u = unit_name(role, factor);
  if (!u.empty()) return ": likely in " + u + " (--units " + role + "=" + u + ")";
  const std::string p = prefixed_unit(role, factor);
  return p.empty() ? std::string()
                   : ": likely in " + p + " (--units " + role + fmt("=counts:%g: %g ", factor, factor) +
                         prefixed_unit(role, 1.0) + " per unit)";
}

}  // namespace

std::string unit_name(const std::string& role, double factor) {
  const auto near = [&](double f) { return std::abs(std::log10(factor / f)) < 0.01; };
  if (role == "t") return near(1) ? "s" : near(1e-3) ? "ms" : near(1e-6) ? "us" : "";
  if (role == "x" || role == "xd")
    return near(1) ? "m" : near(1e-3) ? "mm" : near(1e-6) ? "um" : near(1e-9) ? "nm" : "";
  if (role == "force") return near(1) ? "N" : near(1e3) ? "kN" : near(1e-3) ? "mN" : "";
  if (role == "u") return near(1) ? "V" : near(1e-3) ? "mV" : "";
  return "";
}

namespace {

// The sample k >= 1 after the largest time step t_k - t_k-1.
std::size_t largest_time_step(const MeasuredData& d) {
  std::size_t worst = 1;
  for (std::size_t k = 1; k < d.size(); ++k)
    if (d.t[k] - d.t[k - 1] > d.t[worst] - d.t[worst - 1]) worst = k;
  return worst;
}

// 1. gaps and jumps in time: the largest time step, against kMaxGap median periods T.
void check_time_steps(const MeasuredData& d, double T) {
  const std::size_t worst = largest_time_step(d);
  const double gap = d.t[worst] - d.t[worst - 1];
  if (gap > kMaxGap * T)
    throw DataError(
        d.where(worst) + ": column '" + d.time_name + "': the time jumps by " +
        fmt("%.6g s (%.3g sample periods of %.3g s) from t = %.9g", gap, gap / T, T, d.t[worst - 1] + d.time_offset) +
        fmt(" to %.9g s: a gap, or two recordings joined; the fit needs one continuous recording: split the "
            "file there and fit each part",
            d.t[worst] + d.time_offset));
}

// The 99th percentile of the speed |x_k - x_k-1| / (t_k - t_k-1) [m/s]: an isolated outlier is no
// unit (it is named by the jump check, or by prepare()'s finiteness check).
double speed_p99(const MeasuredData& d) {
  std::vector<double> speed;
  speed.reserve(d.size());
  for (std::size_t k = 1; k < d.size(); ++k) speed.push_back(std::abs(d.x[k] - d.x[k - 1]) / (d.t[k] - d.t[k - 1]));
  return order_statistic(speed, static_cast<std::size_t>(0.99 * static_cast<double>(speed.size() - 1)));
}

// 2. the time scale: a median period T a power of 1000 away from the control period. A period
// 1000x shorter in a unit --units has no name for (t in s, the values in ks) is refused only when
// the speed confirms it (beyond kMaxSpeed: time divided by 1000 multiplies it by 1000): a logger
// may sample 30x faster than the controller runs. Checked before the position, whose speed check
// the same record fails (issue 20's review: it named column x).
void check_time_scale(const MeasuredData& d, double T, double control_period) {
  if (!(control_period > 0 && T > 0)) return;
  const int k = thousands(T / control_period);
  // a record sampled slower than the controller runs: the thrust changes between two samples,
  // while the force residual and the replay hold each sample's over its interval (issue 20's review)
  if (k == 0 && T > kMaxSamplePeriodRatio * control_period)
    throw DataError(d.source + ": column '" + d.time_name + "'" +
                    fmt(": median sample period %.4g s is %.3g times the scenario's control period %.4g s: the "
                        "thrust changes between samples, which the fit takes as held over each; record at the "
                        "control rate (every control period), or give the scenario the logger's period",
                        T, T / control_period, control_period));
  if (k == 0) return;
  const double factor = d.time_factor * std::pow(1000.0, -k);
  std::string h = hint("t", factor);
  // a ratio no power of 1000 gives (within_factor: e.g. 100 us ticks read as s, 1e4): the unit that
  // makes the period one control period, which is what a logger of the loop records (issue 20's
  // review: 100 us ticks were "likely in ms")
  if (k > 0 && !within_factor(T / control_period, std::pow(1000.0, k)))
    h = fmt(": no power of 1000; one sample per control period makes its unit %.3g s (--units t=counts:%.3g)",
            d.time_factor * control_period / T, d.time_factor * control_period / T);
  if (h.empty() || (k < 0 && unit_name("t", factor).empty() && !(speed_p99(d) > kMaxSpeed))) return;
  throw DataError(d.source + ": column '" + d.time_name + "'" +
                  fmt(": median sample period %.4g s against the scenario's control period %.4g s", T, control_period) +
                  (k < 0 ? fmt(", speeds up to %.4g m/s (99th percentile)", speed_p99(d)) : std::string()) + h);
}

// 3. the position scale: travel and speed a feed drive can have (kMaxTravel, kMaxSpeed). The
// travel is the range between the 0.1th and 99.9th percentiles and the speed the 99th percentile
// (speed_p99). A position 1000x too small is the force check's (check_force_scale).
// The position column holds whole numbers only (before its unit's factor): encoder counts, more
// likely than a power of 1000 of a metre.
bool whole_numbers(const MeasuredData& d) {
  for (double x : d.x) {
    const double r = x / d.position_factor;
    if (std::abs(r - std::round(r)) > 1e-9 * std::max(1.0, std::abs(r))) return false;
  }
  return true;
}

// The hint for counts: the encoder's step from plant.sensor.quantization when the scenario gives it.
std::string counts_hint(double quantization) {
  return quantization > 0 ? fmt(": whole numbers: likely encoder counts (--units x=counts:%.6g, the step of "
                                "plant.sensor.quantization)",
                                quantization)
                          : std::string(
                                ": whole numbers: likely encoder counts (--units x=counts:STEP, STEP the "
                                "encoder's step in m)");
}

// The thrust against mass x acceleration (alpha, 1 for a record in the model's units), fitted over
// the record with a constant and a generic friction (sign and viscous) by the modulating-function
// balance, on the filter points; NaN where the acceleration does not carry half the thrust's
// variance (R^2 <= 0.5: no evidence either way).
double balance_ratio(const Record& rec, const plant::PlantParams& model) {
  const long n = static_cast<long>(rec.bank.tau.size());
  const double mass = plant::effective_params(model).mass;
  const double gain = thrust_per_input(rec, model);
  const Eigen::VectorXd thrust = apply(rec.bank, gain * rec.input);
  const long ni = static_cast<long>(rec.motion.v_mid.size());
  Eigen::VectorXd sg(ni), v(ni), one = Eigen::VectorXd::Ones(ni);
  const double v_small = std::max(1e-5, 0.01 * rec.v_max_abs);
  for (long j = 0; j < ni; ++j) {
    v[j] = rec.motion.v_mid[static_cast<std::size_t>(j)];
    sg[j] = std::tanh(v[j] / v_small);
  }
  Eigen::MatrixXd A(n, 4);
  A.col(0) = mass * Eigen::Map<const Eigen::VectorXd>(rec.bank.accel.data(), n);
  A.col(1) = apply(rec.bank, one);
  A.col(2) = apply(rec.bank, sg);
  A.col(3) = apply(rec.bank, v);
  // scale the columns: the solve must not depend on the units of the others
  Eigen::VectorXd s(4);
  for (int c = 0; c < 4; ++c) s[c] = std::max(A.col(c).norm(), 1e-300);
  const Eigen::MatrixXd As = A * s.cwiseInverse().asDiagonal();
  const Eigen::VectorXd beta = As.colPivHouseholderQr().solve(thrust).cwiseQuotient(s);
  const double alpha = beta[0];
  // only a well-determined ratio: the acceleration column must carry the thrust (R^2 of the fit)
  const Eigen::VectorXd res = thrust - A * beta;
  const double r2 = 1.0 - res.squaredNorm() / std::max(thrust.squaredNorm(), 1e-300);
  return r2 > 0.5 && std::abs(alpha) > 0 ? alpha : std::numeric_limits<double>::quiet_NaN();
}

// The position's unit from the thrust balance, when the range check refuses it (issue 20's review:
// a position in cm was "likely in mm", snapped to a power of 1000): with the acceleration in the
// file's unit, alpha = F / (m a) is that unit in metres (0.01 for cm), to the mass error's share (a
// 2x mass error gives 2x). Named when within_factor of a common unit, else given as counts:SCALE;
// "" when the balance cannot say (the record too short to filter, or R^2 <= 0.5).
std::string balance_unit_hint(const MeasuredData& d, const plant::PlantParams& model) {
  double alpha = std::numeric_limits<double>::quiet_NaN();
  try {
    alpha = balance_ratio(prepare(d), model);
  } catch (const std::exception&) {
    return "";
  }
  if (!(alpha > 0)) return "";
  const double unit = alpha * d.position_factor;  // metres per unit of the file
  struct Named {
    const char* name;
    double metres;
    const char* option;
  };
  static const Named known[] = {{"mm", 1e-3, "x=mm"},
                                {"um", 1e-6, "x=um"},
                                {"nm", 1e-9, "x=nm"},
                                {"cm", 1e-2, "x=counts:0.01"},
                                {"inches", 0.0254, "x=counts:0.0254"},
                                {"0.1 mm", 1e-4, "x=counts:0.0001"}};
  const std::string said = fmt(": the thrust balance makes its unit about %.3g m", unit);
  for (const Named& k : known)
    if (within_factor(unit, k.metres)) return said + ": likely in " + k.name + " (--units " + k.option + ")";
  return said + fmt(" (--units x=counts:%.2g)", unit);
}

void check_position_scale(const MeasuredData& d, const plant::PlantParams& model) {
  const double quantization = model.sensor.quantization;
  const std::size_t n = d.size();
  std::vector<double> xs = d.x;
  std::sort(xs.begin(), xs.end());
  const double travel = xs[static_cast<std::size_t>(0.999 * static_cast<double>(n - 1))] -
                        xs[static_cast<std::size_t>(0.001 * static_cast<double>(n - 1))];
  const double v99 = speed_p99(d);
  if (!(travel > kMaxTravel || v99 > kMaxSpeed)) return;
  int k = 0;
  while (k < 4 && (travel * std::pow(1e-3, k) > kMaxTravel || v99 * std::pow(1e-3, k) > kMaxSpeed)) ++k;
  std::string h = balance_unit_hint(d, model);
  if (h.empty()) h = hint("x", d.position_factor * std::pow(1e-3, k));
  throw DataError(d.source + ": column '" + d.position_name + "'" +
                  fmt(": a travel of %.4g m at speeds up to %.4g m/s (99th percentile) is beyond a feed drive (at most "
                      "%.3g m, %.3g m/s)",
                      travel, v99, kMaxTravel, kMaxSpeed) +
                  (whole_numbers(d) ? counts_hint(quantization)
                   : h.empty()      ? ": is the position in metres?"
                                    : h));
}

// The offset o_j of sample j from the straight line through its two neighbours, at t_j: -a h0 h1 / 2
// for a smooth motion of acceleration a, without squaring x (an outlier of 1e308 m stays finite).
// A step of the position by J between samples k-1 and k gives the doublet o_(k-1) = -J/2,
// o_k = +J/2 (equal periods); a spike of J at sample j the triplet -J/2, +J, -J/2; a step of the
// thrust only a change of level. 0 at both ends.
std::vector<double> offsets(const MeasuredData& d) {
  std::vector<double> o(d.size(), 0.0);
  for (std::size_t j = 1; j + 1 < d.size(); ++j) {
    const double h0 = d.t[j] - d.t[j - 1], h1 = d.t[j + 1] - d.t[j];
    o[j] = d.x[j] - (h1 / (h0 + h1)) * d.x[j - 1] - (h0 / (h0 + h1)) * d.x[j + 1];
  }
  return o;
}

// The sample whose second difference |x''_k| (three-point, unequal steps) most exceeds the larger
// of 4x what the peak thrust gives the mass (a mass error of 2x and the friction's share stay
// below it), 50x the sensor's own (a quantum and three noise deviations per step) and 5x the
// record's own 99th percentile (one jump does not move it; jitter's tail stays within 2x of it);
// 0 if none exceeds it.
std::size_t find_jump(const MeasuredData& d, const std::vector<double>& o, double peak, double mass, double sensor) {
  const std::size_t n = d.size();
  std::vector<double> acc(n, 0.0);
  for (std::size_t k = 1; k + 1 < n; ++k)  // |x''_k| = 2 |o_k| / (h0 h1) (offsets)
    acc[k] = 2.0 * std::abs(o[k]) / ((d.t[k] - d.t[k - 1]) * (d.t[k + 1] - d.t[k]));
  const double typical = order_statistic(acc, static_cast<std::size_t>(0.99 * static_cast<double>(n - 1)));
  std::size_t jump = 0;
  double jump_a = 0.0;
  for (std::size_t k = 1; k + 1 < n; ++k) {
    const double h0 = d.t[k] - d.t[k - 1], h1 = d.t[k + 1] - d.t[k];
    const double a = acc[k];
    const double limit = std::max({4.0 * peak / mass, 50.0 * sensor / (h0 * h1), 5.0 * typical});
    if (a > limit && a / limit > jump_a) {
      jump = k;
      jump_a = a / limit;
    }
  }
  return jump;
}

double median3(double a, double b, double c) { return std::max(std::min(a, b), std::min(std::max(a, b), c)); }

// A boundary k (between samples k-1 and k) at which a doublet can be told: three offsets on
// either side, none of them an end's 0.
bool inner(std::size_t k, std::size_t n) { return k >= 5 && n >= 5 && k <= n - 5; }

// e_(k-1): o_(k-1) less the median of the three offsets before it (the level of the motion there).
double departure(const std::vector<double>& o, std::size_t k) {
  return o[k - 1] - median3(o[k - 4], o[k - 3], o[k - 2]);
}

// The evidence of a step of the position between samples k-1 and k: e_(k-1) (departure) and e_k,
// o_k less the median of the three offsets after it (each side its own level: a step of the
// thrust changes the level once and leaves one of the two at 0, where one level for both would
// split it into a doublet). A step of J gives -J/2 and +J/2: size e_k - e_(k-1); strength twice
// the smaller magnitude when the two have opposite signs, else 0 (also where k is not inner).
struct Doublet {
  double size = 0.0, strength = 0.0;
};
Doublet doublet(const std::vector<double>& o, std::size_t k) {
  if (!inner(k, o.size())) return {};
  const double before = departure(o, k);
  const double after = o[k] - median3(o[k + 1], o[k + 2], o[k + 3]);
  if (!(before * after < 0)) return {};
  return {after - before, 2.0 * std::min(std::abs(before), std::abs(after))};
}

// The boundary k (a step between samples k-1 and k) whose doublet is strongest beyond the larger
// of kStepSensor sensor steps (q + 3 noise deviations) and kStepScale times the record's own
// scale of one side of a doublet (|e| over the record, its 99.9th percentile with at least ten
// values above: a step (2 of them) or a spike (3) cannot set its own scale); 0 if none is.
// Measured (27 Nov, a probe printing each record's strongest doublet, not kept): the strongest
// doublet of a valid record is 3.2 sensor steps on the 10 s cogging record of docs/fit.md (50 nm
// encoder, 20 nm noise), 7.0 on the EMPS record (its own 50 nm step, noise unknown), and up to
// 147 on the independent generator's records (a noisy thrust moves the second difference sample
// to sample), which their own scale takes: at most 3.4x it over 920 records of both mixes (400
// each on seeds 7 and 8, 60 each on 101 and 202), 2.0x on the cogging record, 1.8x on EMPS:
// passed with a margin of 2.4x. A 5 um step in the cogging record is 44 sensor steps and 24x its
// scale: caught with margins of 2.2x and 3.0x (a 10 um step in the CI record: 89 and 65).
constexpr double kStepSensor = 20.0, kStepScale = 8.0;
struct Step {
  std::size_t k = 0;                   ///< the boundary, 0 if none
  double strength = 0.0, scale = 0.0;  ///< its doublet's strength and the record's scale [m]
};
Step find_step(const std::vector<double>& o, double sensor) {
  const std::size_t n = o.size();
  std::vector<double> side;
  side.reserve(n);
  for (std::size_t k = 5; inner(k, n); ++k) side.push_back(std::abs(departure(o, k)));
  const std::size_t above = std::max<std::size_t>(10, side.size() / 1000);
  if (side.size() <= above) return {};
  Step best;
  best.scale = order_statistic(side, side.size() - 1 - above);
  const double limit = std::max(kStepSensor * sensor, kStepScale * best.scale);
  for (std::size_t k = 5; inner(k, n); ++k) {
    const double s = doublet(o, k).strength;
    if (s > limit && s > best.strength) {
      best.k = k;
      best.strength = s;
    }
  }
  return best;
}

// The step J of the position between samples k-1 and k less the motion over that interval (the
// mean of the velocities on either side times its length: a gap in time keeps its motion).
double step_size(const MeasuredData& d, std::size_t k) {
  const double v0 = k >= 2 ? (d.x[k - 1] - d.x[k - 2]) / (d.t[k - 1] - d.t[k - 2]) : 0.0;
  const double v1 = k + 1 < d.size() ? (d.x[k + 1] - d.x[k]) / (d.t[k + 1] - d.t[k]) : 0.0;
  return d.x[k] - d.x[k - 1] - 0.5 * (v0 + v1) * (d.t[k] - d.t[k - 1]);
}

// The DataError of a discontinuity near sample `at` (found by find_jump or find_step), told by
// the doublets of the boundaries at-1 .. at+2: an isolated outlier (a spike at j gives two
// adjacent doublets of opposite signs, at j and j+1) named at its own row with its offset from
// the cubic through its two neighbours on either side; else a step at the strongest boundary
// (the larger step of the two around `at` when no doublet is there: an end of the record), with
// its size less the motion, and the time's own gap when the time jumps there too (more than
// 1.5 median periods T: jitter stays well within it). `why`: what makes it no motion.
[[noreturn]] void throw_jump(const MeasuredData& d, const std::vector<double>& o, std::size_t at, double T,
                             const std::string& why) {
  const std::size_t n = d.size();
  std::size_t k = 0;
  Doublet best;
  for (std::size_t b = std::max<std::size_t>(at, 1) - 1; b <= at + 2; ++b)
    if (doublet(o, b).strength > best.strength) {
      k = b;
      best = doublet(o, b);
    }
  for (std::size_t j : {k - 1, k + 1}) {
    const Doublet partner = doublet(o, j);
    const std::size_t s = std::min(k, j);  // the spike's sample
    if (best.strength > 0 && partner.strength >= 0.5 * best.strength && partner.size * best.size < 0 && s >= 2 &&
        s + 2 < n) {
      const double off = cubic_gap(d.t, d.x, s);
      throw DataError(d.where(s) + ": column '" + d.position_name + "'" +
                      fmt(": position %.6g m at t = %.6g s is an outlier, %.4g mm off the course of its neighbours "
                          "(one sample off, the samples around it agree): is the position column in metres and free "
                          "of outliers?",
                          d.x[s], d.t[s] + d.time_offset, off * 1e3));
    }
  }
  if (best.strength == 0)  // no doublet: the larger of the two steps around `at`
    k = at + 1 < n && std::abs(d.x[at + 1] - d.x[at]) > std::abs(d.x[at] - d.x[at - 1]) ? at + 1 : at;
  const double size = step_size(d, k), gap = d.t[k] - d.t[k - 1];
  const std::string time = fmt(" (t = %.9g s)", d.t[k] + d.time_offset);
  const std::string what =
      gap > 1.5 * T ? "columns '" + d.time_name + "' and '" + d.position_name + "'" +
                          fmt(": the time jumps by %.6g s (%.3g sample periods of %.3g s) and the position by %.4g mm",
                              gap, gap / T, T, size * 1e3) +
                          time
                    : "column '" + d.position_name + "'" +
                          fmt(": the position jumps by %.4g mm in one sample", size * 1e3) + time;
  throw DataError(d.where(k) + ": " + what + ", " + why +
                  ": two recordings joined, or an encoder glitch? The fit needs one continuous recording: split the "
                  "file there and fit each part");
}

// 4. discontinuities in position: an acceleration no thrust of this drive gives, and beyond the
// sensor's own second difference (find_jump), or a step of a few um in a record whose thrust
// alone explains its second difference (find_step); the sensor's quantum is the record's own
// resolution when the scenario gives none.
void check_position_jumps(const MeasuredData& d, const plant::PlantParams& model, double T) {
  const double mass = plant::effective_params(model).mass;
  const double gain = d.input_kind == InputKind::kCommand ? model.thrust_gain() : 1.0;
  double peak = 0.0;
  for (double u : d.input) peak = std::max(peak, std::abs(gain * u));
  double q = model.sensor.quantization;
  if (q == 0.0) q = smallest_position_step(d);
  const double sensor = q + 3.0 * model.sensor.noise_stddev;
  const std::vector<double> o = offsets(d);
  if (const std::size_t jump = find_jump(d, o, peak, mass, sensor))
    throw_jump(d, o, jump, T,
               fmt("an acceleration beyond 4x what the peak thrust of %.4g N gives the %.4g kg mass", peak, mass));
  if (const Step step = find_step(o, sensor); step.k > 0)
    throw_jump(d, o, step.k, T,
               fmt("a step no thrust gives: +J then -J in the second difference, %.3g times the sensor's q + 3 sigma "
                   "and %.3g times the record's own scale of it",
                   step.strength / sensor, step.strength / step.scale));
}

// The DataError of a thrust alpha times m a (alpha ~ 1000^k). The ratio cannot tell a force 1000x
// off from a position 1000x off the other way; the scenario's encoder step q can: a position in
// the declared unit moves in steps of q (its smallest step within 1000^(+-1/2) of q), one 1000x
// off in steps of q 1000^(+-1). The position is named when its steps are off by 1000^-k; the
// force alone when they are q; both are offered when the scenario gives no q.
[[noreturn]] void throw_force_scale(const MeasuredData& d, const plant::PlantParams& model, double alpha, double mass) {
  const int k = thousands(std::abs(alpha));
  const double q = model.sensor.quantization, step = smallest_position_step(d);
  const int kx = q > 0 && step > 0 ? thousands(step / q) : 0;
  const std::string ratio = fmt(
      "the thrust is %.3g times mass x acceleration (%.4g kg; fitted over the record with a constant and a friction)",
      alpha, mass);
  if (q > 0 && kx != 0 && kx == -k)
    throw DataError(d.source + ": column '" + d.position_name + "'" +
                    fmt(": its smallest step %.3g m is %.3g times the scenario's encoder step (plant.sensor."
                        "quantization %.3g m), and ",
                        step, step / q, q) +
                    ratio + hint("x", d.position_factor * std::pow(1000.0, -kx)));
  const bool force = d.input_kind == InputKind::kForce;
  // a ratio no power of 1000 gives (within_factor: a mass error's share): the unit is named by the
  // ratio itself (issue 20's review: a position in inches was "likely in mm"), both ways
  if (!within_factor(std::abs(alpha), std::pow(1000.0, k)))
    throw DataError(d.source + ": columns '" + d.input_name + "' and '" + d.position_name + "': " + ratio +
                    fmt(", no power of 1000: the input's unit is about %.3g of the model's", 1.0 / alpha) +
                    " (--units " + (force ? "force" : "u") + fmt("=counts:%.2g)", d.input_factor / alpha) +
                    (alpha * d.position_factor < 0.5  // a position unit below a metre (cm, inches)
                         ? fmt(", or the position's %.3g m (--units x=counts:%.2g)", alpha * d.position_factor,
                               alpha * d.position_factor)
                         : std::string()));
  const std::string h = hint(force ? "force" : "u", d.input_factor * std::pow(1000.0, -k));
  const bool position_agrees = q > 0 && kx == 0;  // its steps are the encoder's: the position is not off
  throw DataError(d.source + ": column '" + d.input_name + "': " + ratio +
                  (h.empty() ? ": is the input in the model's unit (N for a force, V for a command)?" : h) +
                  (position_agrees ? std::string()
                   : k > 0         ? std::string(", or the position is in larger units than declared")
                   : k < 0         ? std::string(", or the position is in smaller units than declared (mm read as m?)")
                                   : std::string()));
}

// Time gaps shorter than kMaxGap median periods T pass (the filter and the replay use each
// interval's own length, and the thrust is taken as held over it), but the report says so:
// intervals longer than kNoteGap T, their number, the largest with its row, and the samples they
// lack at the period T (issue 20's review: 20 % of the rows dropped, gaps of 2-4 periods, and a
// 9-period gap passed without a word).
std::vector<std::string> gap_notes(const MeasuredData& d, double T) {
  constexpr double kNoteGap = 1.5;
  std::size_t count = 0;
  double missing = 0.0;
  for (std::size_t k = 1; k < d.size(); ++k) {
    const double h = d.t[k] - d.t[k - 1];
    if (!(h > kNoteGap * T)) continue;
    ++count;
    missing += std::round(h / T) - 1.0;
  }
  if (count == 0) return {};
  const std::size_t worst = largest_time_step(d);
  const double largest = d.t[worst] - d.t[worst - 1];
  return {
      fmt("time gaps: %.0f intervals longer than 1.5 sample periods (%.3g ms)", static_cast<double>(count), T * 1e3) +
      fmt(", about %.0f samples (%.2g %%) missing at that period; the largest %.3g periods", missing,
          100.0 * missing / (missing + static_cast<double>(d.size())), largest / T) +
      " at " + d.where(worst) +
      fmt(" (t = %.9g s); the fit takes the stamps as they are and the thrust as held over each interval (a gap hides "
          "how it changed)",
          d.t[worst - 1] + d.time_offset)};
}

}  // namespace

std::vector<std::string> check_record(const MeasuredData& d, const plant::PlantParams& model, double control_period) {
  if (d.size() < 3) return {};
  const double T = d.median_period();
  check_time_steps(d, T);
  check_time_scale(d, T, control_period);
  check_position_scale(d, model);
  check_position_jumps(d, model, T);
  return gap_notes(d, T);
}

void check_force_scale(const Record& rec, const plant::PlantParams& model) {
  const MeasuredData& d = *rec.data;
  const long n = static_cast<long>(rec.bank.tau.size());
  if (n < 8) return;
  // a constant input while the drive moves (a channel switched off): nothing drives the model
  const auto [lo, hi] = std::minmax_element(rec.input.data(), rec.input.data() + rec.input.size());
  if (rec.input.size() > 0 && *lo == *hi && rec.v_max_abs > 0)
    throw DataError(d.source + ": column '" + d.input_name + "'" +
                    fmt(": constant (%.4g) over the whole record while the drive moves (up to %.4g mm/s): a "
                        "channel switched off or the wrong column; the fit needs the thrust or the command",
                        *lo + 0.0, rec.v_max_abs * 1e3));  // + 0.0: -0 prints as 0
  const double mass = plant::effective_params(model).mass;
  const double alpha = balance_ratio(rec, model);
  if (!std::isfinite(alpha)) return;
  // a thrust against the acceleration: the direction of one column is reversed (issue 20's review).
  // Only a ratio in the band a mass error gives, mirrored (-1/kMaxSignRatio and beyond; a negated
  // column gives -1): a small negative one is no evidence, only an acceleration that explains
  // little of a thrust spent on position forces (seed-20 record 40000130, a grinding force and a
  // spring: -0.056)
  if (alpha <= -1.0 / kMaxSignRatio)
    throw DataError(d.source + ": columns '" + d.input_name + "' and '" + d.position_name + "'" +
                    fmt(": the thrust is %.3g times mass x acceleration (%.4g kg): it pushes against the motion, "
                        "so the sign of one of them is reversed (the encoder counting the other way, or the force "
                        "logged with the opposite sign): negate one column",
                        alpha, mass));
  if (std::abs(alpha) <= kMaxForceRatio && std::abs(alpha) >= 1.0 / kMaxForceRatio) return;
  throw_force_scale(d, model, alpha, mass);
}

}  // namespace feeddrive::fit
