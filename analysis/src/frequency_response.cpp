#include "feeddrive/analysis/frequency_response.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "feeddrive/common/fields.hpp"
#include "feeddrive/common/validate.hpp"
#include "feeddrive/sim/simulation.hpp"
#include "feeddrive/sim/summary.hpp"
#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::analysis {
namespace {

constexpr double kPi = 3.14159265358979323846;
using cd = std::complex<double>;

// x = x0 + v*t + A*sin(w t), with its analytic derivatives.
class ExcitationReference final : public trajectory::Trajectory {
 public:
  ExcitationReference(double x0, double v, double a, double w) : x0_(x0), v_(v), a_(a), w_(w) {}
  trajectory::Sample sample(double t) const override {
    const double s = std::sin(w_ * t), c = std::cos(w_ * t);
    return {x0_ + v_ * t + a_ * s, v_ + a_ * w_ * c, -a_ * w_ * w_ * s, -a_ * w_ * w_ * w_ * c};
  }
  double end_time() const override { return std::numeric_limits<double>::infinity(); }

 private:
  double x0_, v_, a_, w_;
};

// One run at one frequency: the phasors of the error e = xd - x, of the controller's force F_c
// and of the excitation, per block.
struct Run {
  cd e[2], fc[2], in[2];
  double se[2]{0, 0}, see[2]{0, 0};
  long saturated{0};
};

struct Plan {
  double f;  // moved to whole cycles: M cycles in N samples
  long settle, n;
};

// The plan in doubles (M, N and the settling may be beyond any long for an option that cannot be
// meant: validate refuses those before plan() converts).
struct PlanSize {
  double f, settle, n, m;
};

PlanSize plan_size(double f, double T, const FrequencyResponseOptions& o) {
  const double m = std::max<double>(o.block_cycles, std::ceil(o.block_time * f));
  const double n = std::max(1.0, std::round(m / (f * T)));
  const double f_whole = m / (n * T);
  const double settle = std::round(std::max(o.settle_cycles / f_whole, o.settle_time) / T);
  return {f_whole, settle, n, m};
}

Plan plan(double f, double T, const FrequencyResponseOptions& o) {
  const PlanSize p = plan_size(f, T, o);
  return {p.f, static_cast<long>(p.settle), static_cast<long>(p.n)};
}

// The measured range of a field of the reference's list (reference.max_velocity for --fr-velocity).
struct MetaOf {
  const char* name;
  fields::Meta meta{};
  template <typename T>
  void Visit(const fields::Field<T>& f) {
    if (std::string(f.meta.name) == name) meta = f.meta;
  }
};

fields::Meta max_velocity_meta() {
  trajectory::AccelLimitedParams p;
  MetaOf m{"max_velocity"};
  p.Serialize(&m);
  return m.meta;
}

Run run_once(const sim::Scenario& base, const Plan& p, double ref_amplitude, double force_amplitude, double v_feed,
             const interrupt::StopToken& stop) {
  sim::Scenario s = base;
  const double T = s.control_period;
  s.duration = static_cast<double>(p.settle + 2 * p.n) * T;
  const double w = 2.0 * kPi * p.f;
  const ExcitationReference ref(s.plant.initial.position, v_feed, ref_amplitude, w);
  sim::Excitation ex;
  ex.reference = &ref;
  ex.stop = stop;
  if (force_amplitude != 0.0) ex.input_force = [&](double t) { return force_amplitude * std::sin(w * t); };
  const double kf = s.plant.thrust_gain();
  Run r;
  long k = 0;
  sim::run(
      s,
      [&](const sim::Record& q) {
        const long j = k++ - p.settle;
        if (j < 0) return;
        const int b = j < p.n ? 0 : 1;
        const cd rot = std::polar(1.0, -w * q.t);  // t_k = k*T exactly (Scenario::time_of)
        const double e = q.xd - q.x;
        const double input =
            force_amplitude != 0.0 ? force_amplitude * std::sin(w * q.t) : ref_amplitude * std::sin(w * q.t);
        r.e[b] += e * rot;
        r.fc[b] += kf * q.u * rot;
        r.in[b] += input * rot;
        r.se[b] += e;
        r.see[b] += e * e;
        if (q.u != q.u_unsaturated) ++r.saturated;
      },
      ex);
  const double scale = 2.0 / static_cast<double>(p.n);
  for (int b = 0; b < 2; ++b) {
    r.e[b] *= scale;
    r.fc[b] *= scale;
    r.in[b] *= scale;
  }
  return r;
}

// share of the position's power at frequencies other than f: the error's variance less its
// fundamental, against the position's fundamental (X)
double nonfundamental(const Run& r, long n, cd x_fund) {
  const double nn = 2.0 * static_cast<double>(n);
  const double mean = (r.se[0] + r.se[1]) / nn;
  const double var = (r.see[0] + r.see[1]) / nn - mean * mean;
  const cd e = 0.5 * (r.e[0] + r.e[1]);
  const double other = std::max(0.0, var - 0.5 * std::norm(e));
  const double fund = 0.5 * std::norm(x_fund);
  return fund + other > 0.0 ? std::sqrt(other / (fund + other)) : 0.0;
}

double drift(cd h1, cd h2) {
  const cd h = 0.5 * (h1 + h2);
  return std::abs(h) > 0.0 ? std::abs(h1 - h2) / std::abs(h) : 0.0;
}

FrequencyPoint measure_point(const sim::Scenario& s, const FrequencyResponseOptions& o, double a_lim, double f) {
  const Plan p = plan(f, s.control_period, o);
  const double w = 2.0 * kPi * p.f;
  FrequencyPoint pt;
  pt.frequency_hz = p.f;
  if (o.reference_amplitude > 0.0) {
    pt.reference_amplitude_m = std::min(o.reference_amplitude, a_lim / (w * w));
    const Run r = run_once(s, p, pt.reference_amplitude_m, 0.0, o.feed_velocity, o.stop);
    cd t[2];
    for (int b = 0; b < 2; ++b) t[b] = 1.0 - r.e[b] / r.in[b];  // X/R = (R - E)/R
    pt.closed_loop = 0.5 * (t[0] + t[1]);
    pt.closed_loop_drift = drift(t[0], t[1]);
    const cd rr = 0.5 * (r.in[0] + r.in[1]);
    pt.closed_loop_nonfundamental = nonfundamental(r, p.n, rr - 0.5 * (r.e[0] + r.e[1]));
    pt.saturated_steps += r.saturated;
    pt.has_reference = true;
  }
  if (o.force_amplitude > 0.0) {
    const Run r = run_once(s, p, 0.0, o.force_amplitude, o.feed_velocity, o.stop);
    cd g[2], si[2], l[2];
    for (int b = 0; b < 2; ++b) {
      g[b] = -r.e[b] / r.in[b];
      si[b] = (r.fc[b] + r.in[b]) / r.in[b];
      l[b] = -r.fc[b] / (r.fc[b] + r.in[b]);
    }
    pt.compliance = 0.5 * (g[0] + g[1]);
    pt.sensitivity = 0.5 * (si[0] + si[1]);
    pt.loop = 0.5 * (l[0] + l[1]);
    pt.disturbance_drift = drift(g[0], g[1]);
    pt.disturbance_nonfundamental = nonfundamental(r, p.n, -0.5 * (r.e[0] + r.e[1]));
    pt.saturated_steps += r.saturated;
    pt.has_disturbance = true;
  }
  return pt;
}

double db(cd h) { return 20.0 * std::log10(std::abs(h)); }

// linear interpolation of y at the crossing of g through level between points i-1 and i, in log f
double cross_log_f(double f0, double f1, double g0, double g1, double level) {
  const double a = (level - g0) / (g1 - g0);
  return std::exp(std::log(f0) + a * (std::log(f1) - std::log(f0)));
}

}  // namespace

std::vector<double> FrequencyResponseOptions::requested(const sim::Scenario& s) const {
  std::vector<double> fs = frequencies;
  if (fs.empty()) {
    const double hi = f_max > 0.0 ? f_max : 0.4 / s.control_period;
    for (int i = 0; i < points; ++i)
      fs.push_back(points == 1 ? f_min : f_min * std::pow(hi / f_min, static_cast<double>(i) / (points - 1)));
  }
  std::sort(fs.begin(), fs.end());
  return fs;
}

double FrequencyResponseOptions::total_steps(const sim::Scenario& s) const {
  const double runs = (reference_amplitude > 0.0 ? 1.0 : 0.0) + (force_amplitude > 0.0 ? 1.0 : 0.0);
  double steps = 0.0;
  for (double f : requested(s)) {
    const PlanSize p = plan_size(f, s.control_period, *this);
    steps += runs * (p.settle + 2.0 * p.n);
  }
  return steps;
}

std::vector<std::string> FrequencyResponseOptions::warnings() const {
  std::vector<std::string> out;
  fields::PlausibilityArchive a("", &out);
  double speed = std::abs(feed_velocity);
  fields::Field<double> f{max_velocity_meta(), &speed};
  f.meta.name = "--fr-velocity";
  a.Visit(f);
  return out;
}

void FrequencyResponseOptions::validate(const sim::Scenario& s) const {
  const auto bad = [](const std::string& option, double v, const std::string& why) {
    throw std::invalid_argument(option + " " + validate::format_number(v) + ": " + why);
  };
  if (s.controller.type == sim::ControllerType::kOpenLoop)
    throw std::invalid_argument(
        "controller.type open_loop: no feedback loop to measure (the frequency response needs a "
        "closed loop: sliding_mode, cascade or plugin)");
  const double nyquist = 0.5 / s.control_period;
  const std::string below = "below Nyquist " + validate::format_number(nyquist) + " Hz";
  for (double f : frequencies)
    if (!(f > 0.0) || !(f < nyquist)) bad("--fr-frequencies", f, "must be > 0 and " + below);
  if (frequencies.empty()) {
    if (!(f_min > 0.0) || !(f_min < nyquist)) bad("--fr-from", f_min, "must be > 0 and " + below);
    if (f_max != 0.0 && (!(f_max > f_min) || !(f_max < nyquist)))
      bad("--fr-to", f_max, "must be above --fr-from and " + below);
    if (points < 1 || points > 1000) bad("--fr-points", points, "must be 1 to 1000");
  }
  if (!(reference_amplitude >= 0.0) || !std::isfinite(reference_amplitude))
    bad("--fr-amplitude", reference_amplitude, "must be >= 0 [m]");
  if (!(force_amplitude >= 0.0) || !std::isfinite(force_amplitude))
    bad("--fr-force", force_amplitude, "must be >= 0 [N]");
  if (reference_amplitude == 0.0 && force_amplitude == 0.0)
    bad("--fr-amplitude", 0.0, "and --fr-force 0: nothing to measure");
  if (!(acceleration_limit >= 0.0) || !std::isfinite(acceleration_limit))
    bad("--fr-acceleration", acceleration_limit, "must be >= 0 [m/s^2]");
  // the hard bound of reference.max_velocity (trajectory.hpp), with its likely unit
  const fields::Meta vmax = max_velocity_meta();
  if (!std::isfinite(feed_velocity) || std::abs(feed_velocity) > vmax.max)
    bad("--fr-velocity", feed_velocity,
        "must be within +-" + validate::format_number(vmax.max) + " m/s, as reference.max_velocity (" + vmax.hint_high +
            "?)");
  if (!(settle_cycles >= 0.0) || !(settle_time >= 0.0) || !std::isfinite(settle_time))
    bad("--fr-settle", settle_time, "must be >= 0 and finite [s]");
  if (block_cycles < 1) bad("block_cycles", block_cycles, "must be >= 1");
  if (jobs < 1 || jobs > 256) bad("--jobs", jobs, "is outside [1, 256]");
  // A frequency moved to whole cycles (M/(N T)) must stay below Nyquist: on it, sin(pi k) = 0.
  for (double f : requested(s)) {
    const PlanSize p = plan_size(f, s.control_period, *this);
    if (p.f >= nyquist)
      bad(frequencies.empty() ? "--fr-to" : "--fr-frequencies", f,
          "is measured as " + validate::format_number(p.m) + " cycles in " + validate::format_number(p.n) +
              " samples, i.e. at " + validate::format_number(p.f) + " Hz: must be " + below);
  }
  // The whole measurement is bounded as a scenario's run is (docs/scenario.md, Limits).
  if (const double n = total_steps(s); !(n <= sim::kMaxSteps)) {
    char buf[320];
    const std::vector<double> fs = requested(s);
    std::snprintf(
        buf, sizeof buf,
        "frequency response: %.3g steps (%zu frequencies from %.4g Hz, --fr-settle %.4g s); a run has at most %.3g "
        "steps (docs/scenario.md, Limits): a higher lowest frequency or a shorter --fr-settle",
        n, fs.size(), fs.front(), settle_time, sim::kMaxSteps);
    throw std::invalid_argument(buf);
  }
}

FrequencyResponse measure_frequency_response(const sim::Scenario& s, const FrequencyResponseOptions& o) {
  o.validate(s);
  const auto t0 = std::chrono::steady_clock::now();
  FrequencyResponse r;
  r.options = o;
  r.warnings = s.warnings;
  for (const std::string& w : o.warnings()) r.warnings.push_back(w);
  const std::vector<double> fs = o.requested(s);
  // a quarter of the controller's force range (half of u_max - u_min) over the mass
  r.acceleration_limit = o.acceleration_limit > 0.0
                             ? o.acceleration_limit
                             : 0.25 * 0.5 * sim::controller_output_range(s) * s.plant.thrust_gain() / s.plant.mass;
  r.points.resize(fs.size());
  // A plugin may keep state of its own: one at a time.
  const int jobs =
      s.controller.type == sim::ControllerType::kPlugin ? 1 : std::min<int>(o.jobs, static_cast<int>(fs.size()));
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex m;
  const auto work = [&] {
    for (std::size_t i = next++; i < fs.size(); i = next++) {
      try {
        r.points[i] = measure_point(s, o, r.acceleration_limit, fs[i]);
      } catch (...) {
        std::lock_guard<std::mutex> lock(m);
        if (!error) error = std::current_exception();
        next = fs.size();
      }
    }
  };
  std::vector<std::thread> pool;
  for (int j = 1; j < jobs; ++j) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  compute_figures(r);
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

std::vector<double> unwrapped_phase_deg(const std::vector<std::complex<double>>& h, bool negative_start) {
  std::vector<double> phase(h.size(), 0.0);
  for (std::size_t i = 0; i < h.size(); ++i) {
    double a = std::arg(h[i]) * 180.0 / kPi;
    if (i == 0) {
      if (negative_start && a > 0.0) a -= 360.0;
    } else {
      while (a - phase[i - 1] > 180.0) a -= 360.0;
      while (a - phase[i - 1] < -180.0) a += 360.0;
    }
    phase[i] = a;
  }
  return phase;
}

void compute_figures(FrequencyResponse& r) {
  {  // every figure from these points only (a copy with other points is computed afresh)
    FrequencyResponse fresh;
    fresh.options = r.options;
    fresh.acceleration_limit = r.acceleration_limit;
    fresh.points = std::move(r.points);
    fresh.warnings = std::move(r.warnings);
    fresh.wall_time_s = r.wall_time_s;
    r = std::move(fresh);
  }
  // A doubtful point supplies no figure: its ratio is not a frequency response.
  std::vector<const FrequencyPoint*> ref, dist;
  for (const FrequencyPoint& q : r.points) {
    if (q.has_reference && !q.reference_doubtful()) ref.push_back(&q);
    if (q.has_disturbance && !q.disturbance_doubtful()) dist.push_back(&q);
  }
  const double kBw = -20.0 * std::log10(std::sqrt(2.0));  // -3.01 dB
  std::size_t imax = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    const double g = db(ref[i]->closed_loop);
    if (std::isnan(r.peak_db) || g > r.peak_db) r.peak_db = g, r.peak_hz = ref[i]->frequency_hz, imax = i;
    if (std::isnan(r.bandwidth_hz) && g < kBw && i > 0 && db(ref[i - 1]->closed_loop) >= kBw) {
      r.bandwidth_hz = cross_log_f(ref[i - 1]->frequency_hz, ref[i]->frequency_hz, db(ref[i - 1]->closed_loop), g, kBw);
      r.bandwidth_between_hz[0] = ref[i - 1]->frequency_hz;
      r.bandwidth_between_hz[1] = ref[i]->frequency_hz;
    }
  }
  // a resonance peak is a maximum inside the range; at its edge it is only where the range stops
  r.peak_inside = ref.size() >= 3 && imax > 0 && imax + 1 < ref.size();
  if (!ref.empty() && std::isnan(r.bandwidth_hz)) r.bandwidth_outside = db(ref.front()->closed_loop) < kBw ? -1 : 1;
  for (const FrequencyPoint* q : dist) {
    const double ms = std::abs(q->sensitivity), k = q->stiffness_N_per_um();
    if (std::isnan(r.sensitivity_peak) || ms > r.sensitivity_peak)
      r.sensitivity_peak = ms, r.sensitivity_peak_hz = q->frequency_hz;
    if (std::isnan(r.min_stiffness_N_per_um) || k < r.min_stiffness_N_per_um)
      r.min_stiffness_N_per_um = k, r.min_stiffness_hz = q->frequency_hz;
  }
  // phase of L unwrapped from the lowest frequency, started in (-360, 0]
  std::vector<cd> loop;
  for (const FrequencyPoint* q : dist) loop.push_back(q->loop);
  const std::vector<double> phase = unwrapped_phase_deg(loop, true);
  const auto f_at = [&](std::size_t i, double a) {
    return std::exp(std::log(dist[i - 1]->frequency_hz) +
                    a * (std::log(dist[i]->frequency_hz) - std::log(dist[i - 1]->frequency_hz)));
  };
  for (std::size_t i = 1; i < dist.size(); ++i) {
    const double g0 = db(dist[i - 1]->loop), g1 = db(dist[i]->loop);
    if (g0 >= 0.0 && g1 < 0.0) {
      const double a = (0.0 - g0) / (g1 - g0);
      r.crossover_hz = f_at(i, a);
      double pm = 180.0 + phase[i - 1] + a * (phase[i] - phase[i - 1]);
      pm = std::fmod(pm, 360.0);
      if (pm > 180.0) pm -= 360.0;
      if (pm <= -180.0) pm += 360.0;
      r.phase_margin_deg = pm;
      break;
    }
  }
  if (std::isnan(r.crossover_hz)) return;
  // Every crossing of -180 + n*360 (MATLAB allmargin): above the crossover the first one going
  // down is the gain margin; below it (a conditionally stable loop, |L| > 1 there) the one nearest
  // 0 dB is the lower gain margin: lowering the gain by that much makes the loop unstable.
  for (std::size_t i = 1; i < dist.size(); ++i) {
    const double k0 = std::floor((phase[i - 1] + 180.0) / 360.0), k1 = std::floor((phase[i] + 180.0) / 360.0);
    if (k0 == k1) continue;
    const double level = std::max(k0, k1) * 360.0 - 180.0;
    const double a = (level - phase[i - 1]) / (phase[i] - phase[i - 1]);
    const double gm = -(db(dist[i - 1]->loop) + a * (db(dist[i]->loop) - db(dist[i - 1]->loop)));
    const double f = f_at(i, a);
    if (f < r.crossover_hz) {
      if (std::isnan(r.lower_gain_margin_db) || gm > r.lower_gain_margin_db)
        r.lower_gain_margin_db = gm, r.lower_phase_crossover_hz = f;
    } else if (k1 < k0) {
      r.gain_margin_db = gm, r.phase_crossover_hz = f;
      break;
    }
  }
}

}  // namespace feeddrive::analysis
