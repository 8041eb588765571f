#include "feeddrive/fit/identify.hpp"

#include <ceres/ceres.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/fit/plausibility.hpp"
#include "feeddrive/plant/effects.hpp"

namespace feeddrive::fit {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr const char* kSmoothing = "friction.static_smoothing_velocity";
constexpr const char* kOffset = "form.direction_asymmetry";
constexpr const char* kExponent = "friction.stribeck_exponent";

struct Ctx {
  const Record& rec;
  const plant::PlantParams& model;
  const Eigen::VectorXd* r0;  // residual of the model without the candidate (may be null)
  double x_mean;
  double offset_bound{0.0};     // |F| bound of the model-form offset (FreeSet::offset_bound)
  interrupt::StopToken stop{};  // ends a solve within an iteration (Ctrl-C in the tool)
};

double x_mean_of(const Record& rec) {
  const auto& x = rec.data->x;
  return std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(x.size());
}

using Theta = std::vector<double>;

// One candidate: its optimisation vector theta <-> vocabulary parameters, its starts, bounds.
struct Spec {
  std::string name;
  int dim;
  std::vector<int> fixed;  // theta entries held constant by Ceres (scanned by the starts)
  std::function<Effect(const Theta&, const Ctx&)> to_effect;
  std::function<Theta(const Effect&, const Ctx&)> from_effect;
  std::function<std::vector<Theta>(const Ctx&)> starts;
  std::vector<std::pair<int, double>> lower;
  /// Upper bounds; they may depend on the record (e.g. the filter window).
  std::function<std::vector<std::pair<int, double>>(const Ctx&)> upper;
  /// Equivalent parametrisations of a solution to try as well (kept if at least as good).
  std::function<std::vector<Theta>(const Theta&)> alternatives;
};

// Best pitches of a ripple-like regressor  r0 ~ A sin(kappa x) + B cos(kappa x)  (times the
// thrust for reluctance), by a periodogram over the wavenumber kappa. Returns {pitch, A, B}
// (the effect's own coefficients: r0 = -filtered F_extra) of the three strongest local maxima.
std::vector<std::array<double, 3>> pitch_periodogram(const Ctx& c, bool times_thrust) {
  const Record& rec = c.rec;
  const Motion& m = rec.motion;
  const long ni = static_cast<long>(m.x_mid.size());
  const double range = std::max(rec.x_max - rec.x_min, 1e-4);
  // The pitches plausibility.hpp admits (Envelope::min_pitch, max_pitch).
  const Envelope env = envelope(rec, c.model);
  const double p_max = env.max_pitch();
  const double p_min = env.min_pitch();
  if (p_min > p_max) return {};
  const double k_lo = 2 * kPi / p_max, k_hi = 2 * kPi / p_min, dk = 2 * kPi / (8.0 * range);
  const double gain = thrust_per_input(rec, c.model);
  const Eigen::VectorXd& r0 = *c.r0;
  std::vector<double> kappa, gain_rss;
  std::vector<std::array<double, 2>> coef;
  Eigen::VectorXd s(ni), co(ni);
  for (double k = k_lo; k <= k_hi && kappa.size() < 4000; k += dk) {
    for (long j = 0; j < ni; ++j) {
      const double f = times_thrust ? gain * rec.input[j] : 1.0;
      s[j] = f * std::sin(k * m.x_mid[j]);
      co[j] = f * std::cos(k * m.x_mid[j]);
    }
    const Eigen::VectorXd fs = apply(rec.bank, s), fc = apply(rec.bank, co);
    Eigen::Matrix2d A;
    A << fs.dot(fs), fs.dot(fc), fs.dot(fc), fc.dot(fc);
    const Eigen::Vector2d b(fs.dot(r0), fc.dot(r0));
    const Eigen::Vector2d x = A.ldlt().solve(b);
    kappa.push_back(k);
    gain_rss.push_back(std::isfinite(x.dot(b)) ? x.dot(b) : 0.0);
    coef.push_back({-x[0], -x[1]});
  }
  std::vector<std::size_t> peaks;
  for (std::size_t i = 0; i < kappa.size(); ++i) {
    const bool left = i == 0 || gain_rss[i] >= gain_rss[i - 1];
    const bool right = i + 1 == kappa.size() || gain_rss[i] >= gain_rss[i + 1];
    if (left && right) peaks.push_back(i);
  }
  std::sort(peaks.begin(), peaks.end(), [&](std::size_t a, std::size_t b) { return gain_rss[a] > gain_rss[b]; });
  std::vector<std::array<double, 3>> out;
  for (std::size_t q = 0; q < peaks.size() && q < 3; ++q)
    out.push_back({2 * kPi / kappa[peaks[q]], coef[peaks[q]][0], coef[peaks[q]][1]});
  return out;
}

std::vector<double> quantiles(std::vector<double> v, const std::vector<double>& qs) {
  std::sort(v.begin(), v.end());
  std::vector<double> out;
  for (double q : qs) out.push_back(v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))]);
  return out;
}

// long-function: a flat table, one entry per candidate effect (its parameters, bounds and starts);
// splitting it would scatter the table.
const std::vector<Spec>& specs() {
  static const std::vector<Spec> all = [] {
    std::vector<Spec> s;
    const auto one = [](const char* name, const char* param, double start) {
      Spec sp;
      sp.name = name;
      sp.dim = 1;
      const std::string p = param;
      sp.to_effect = [name = std::string(name), p](const Theta& t, const Ctx&) { return Effect{name, {{p, t[0]}}}; };
      sp.from_effect = [p](const Effect& e, const Ctx&) { return Theta{e.parameters.at(p)}; };
      sp.starts = [start](const Ctx&) { return std::vector<Theta>{{start}}; };
      return sp;
    };
    s.push_back(one("constant_force", "force", 0.0));
    // Friction and spring effects have the physical sign the plant requires (>= 0).
    s.push_back(one("coulomb_friction", "coulomb_force", 0.0));
    s.back().lower = {{0, 0.0}};
    s.push_back(one("viscous_friction", "viscous", 0.0));
    s.back().lower = {{0, 0.0}};
    {
      Spec sp;
      sp.name = "stribeck_friction";
      sp.dim = 3;  // Fc, Fs - Fc, ln vs  (Fs >= Fc >= 0, as the plant requires)
      sp.to_effect = [](const Theta& t, const Ctx&) {
        return Effect{"stribeck_friction",
                      {{"static_force", t[0] + t[1]}, {"coulomb_force", t[0]}, {"stribeck_velocity", std::exp(t[2])}}};
      };
      sp.from_effect = [](const Effect& e, const Ctx&) {
        return Theta{e.parameters.at("coulomb_force"),
                     e.parameters.at("static_force") - e.parameters.at("coulomb_force"),
                     std::log(e.parameters.at("stribeck_velocity"))};
      };
      sp.starts = [](const Ctx& c) {
        std::vector<Theta> out;
        const double vmax = std::max(c.rec.v_max_abs, 1e-6);
        for (double f : {0.003, 0.03, 0.3}) out.push_back({0.0, 1.0, std::log(f * vmax)});
        return out;
      };
      sp.lower = {{0, 0.0}, {1, 0.0}};
      s.push_back(sp);
    }
    {
      Spec sp;
      sp.name = "presliding";
      sp.dim = 2;  // ln sigma0, sigma1
      sp.to_effect = [](const Theta& t, const Ctx&) {
        return Effect{"presliding", {{"bristle_stiffness", std::exp(t[0])}, {"bristle_damping", t[1]}}};
      };
      sp.from_effect = [](const Effect& e, const Ctx&) {
        return Theta{std::log(e.parameters.at("bristle_stiffness")), e.parameters.at("bristle_damping")};
      };
      sp.starts = [](const Ctx& c) {
        const double s1 =
            c.model.friction.model == plant::FrictionModel::kLuGre ? c.model.friction.bristle_damping : 0.0;
        std::vector<Theta> out;
        for (double s0 : {1e5, 1e6, 1e7, 1e8}) out.push_back({std::log(s0), s1});
        return out;
      };
      sp.lower = {{1, 0.0}};
      s.push_back(sp);
    }
    {
      Spec sp;
      sp.name = "cogging_ripple";
      sp.dim = 5;  // ln p, a cos(phi), a sin(phi), b cos(phi3), b sin(phi3)
      sp.to_effect = [](const Theta& t, const Ctx&) {
        return Effect{"cogging_ripple",
                      {{"pitch", std::exp(t[0])},
                       {"cogging_amplitude", std::hypot(t[1], t[2])},
                       {"cogging_phase", std::atan2(t[2], t[1])},
                       {"cogging_third", std::hypot(t[3], t[4])},
                       {"cogging_third_phase", std::atan2(t[4], t[3])}}};
      };
      sp.from_effect = [](const Effect& e, const Ctx&) {
        const auto& p = e.parameters;
        return Theta{std::log(p.at("pitch")), p.at("cogging_amplitude") * std::cos(p.at("cogging_phase")),
                     p.at("cogging_amplitude") * std::sin(p.at("cogging_phase")),
                     p.at("cogging_third") * std::cos(p.at("cogging_third_phase")),
                     p.at("cogging_third") * std::sin(p.at("cogging_third_phase"))};
      };
      sp.starts = [](const Ctx& c) {
        std::vector<Theta> out;
        for (const auto& pk : pitch_periodogram(c, false)) out.push_back({std::log(pk[0]), pk[1], pk[2], 0.0, 0.0});
        return out;
      };
      // A ripple of pitch p is also "the third harmonic of pitch 3p": when the fit lands on the
      // latter, the fundamental-only form at p is the same force with the physical pitch.
      sp.alternatives = [](const Theta& t) { return std::vector<Theta>{{t[0] - std::log(3.0), t[3], t[4], 0.0, 0.0}}; };
      s.push_back(sp);
    }
    {
      Spec sp;
      sp.name = "reluctance_ripple";
      sp.dim = 3;  // ln p, A cos(phi), A sin(phi)
      sp.to_effect = [](const Theta& t, const Ctx&) {
        return Effect{"reluctance_ripple",
                      {{"pitch", std::exp(t[0])},
                       {"reluctance_amplitude", std::hypot(t[1], t[2])},
                       {"reluctance_phase", std::atan2(t[2], t[1])}}};
      };
      sp.from_effect = [](const Effect& e, const Ctx&) {
        const auto& p = e.parameters;
        return Theta{std::log(p.at("pitch")), p.at("reluctance_amplitude") * std::cos(p.at("reluctance_phase")),
                     p.at("reluctance_amplitude") * std::sin(p.at("reluctance_phase"))};
      };
      sp.starts = [](const Ctx& c) {
        std::vector<Theta> out;
        for (const auto& pk : pitch_periodogram(c, true)) out.push_back({std::log(pk[0]), pk[1], pk[2]});
        return out;
      };
      s.push_back(sp);
    }
    {
      Spec sp;
      sp.name = "grinding_force";
      sp.dim = 3;  // ln C, ln ke, contact position (scanned, held by Ceres)
      sp.fixed = {2};
      sp.to_effect = [](const Theta& t, const Ctx&) {
        return Effect{"grinding_force",
                      {{"damping", std::exp(t[0])}, {"stiffness", std::exp(t[1])}, {"contact_position", t[2]}}};
      };
      sp.from_effect = [](const Effect& e, const Ctx&) {
        const auto& p = e.parameters;
        return Theta{std::log(p.at("damping")), std::log(p.at("stiffness")), p.at("contact_position")};
      };
      sp.starts = [](const Ctx& c) {
        std::vector<double> qs;
        for (int i = 0; i <= 9; ++i) qs.push_back(0.1 * i);
        std::vector<double> contacts = quantiles(c.rec.data->x, qs);
        contacts.front() = c.rec.x_min - 1e-3;  // always in contact
        std::vector<Theta> out;
        // two time constants C/ke: 10 ms and 3 ms (at a start whose C/ke is far off the truth the
        // fit can run to C/ke -> 0, where ke has no gradient left: fg = C v; issue 20's review:
        // a 3.3 ms grinding force fitted at 0.032 ms)
        for (double xc : contacts) {
          out.push_back({std::log(1e4), std::log(1e6), xc});
          out.push_back({std::log(1e3), std::log(1e3 / 3e-3), xc});
        }
        return out;
      };
      s.push_back(sp);
    }
    {
      Spec sp;
      sp.name = "spring_force";
      sp.dim = 2;  // k, F0 = k*(x_mean - rest)
      sp.to_effect = [](const Theta& t, const Ctx& c) {
        const double rest = std::abs(t[0]) > 1e-12 ? c.x_mean - t[1] / t[0] : c.x_mean;
        return Effect{"spring_force", {{"stiffness", t[0]}, {"rest_position", rest}}};
      };
      sp.from_effect = [](const Effect& e, const Ctx& c) {
        const double k = e.parameters.at("stiffness");
        return Theta{k, k * (c.x_mean - e.parameters.at("rest_position"))};
      };
      sp.starts = [](const Ctx&) { return std::vector<Theta>{{0.0, 0.0}}; };
      sp.lower = {{0, 0.0}};
      s.push_back(sp);
    }
    {
      Spec sp = one("mass_error", "mass", 0.0);
      sp.starts = [](const Ctx& c) { return std::vector<Theta>{{plant::effective_params(c.model).mass}}; };
      sp.lower = {{0, 1e-6}};
      s.push_back(sp);
    }
    {
      Spec sp = one("input_delay", "delay", 0.0);
      sp.starts = [](const Ctx& c) {
        const double T = c.rec.period;
        return std::vector<Theta>{{0.5 * T}, {2.0 * T}, {8.0 * T}};
      };
      // 0 <= delay <= L: a longer delay is outside what one filter window can see.
      sp.lower = {{0, 0.0}};
      sp.upper = [](const Ctx& c) { return std::vector<std::pair<int, double>>{{0, c.rec.bank.half_width}}; };
      s.push_back(sp);
    }
    {
      // Not an effect: the model-form parameters of the smoothed sign (plant/forces.hpp)
      // sgn_eps(v) = (1 - b) tanh(v/eps) + b v/sqrt(v^2 + eps^2): ln eps, between 1 um/s and 2 %
      // of the peak speed (a wider band would stand in for viscous friction), and the shape b in
      // [0, 1]. Real friction changes sign over a finite velocity band of a shape no one knows
      // beforehand; fixing it to tanh leaves the difference to be patched by named effects
      // (Stribeck, viscous, presliding) at the low speeds of reversals and creeping moves.
      Spec sp;
      sp.name = kSmoothing;
      sp.dim = 2;
      sp.lower = {{0, std::log(1e-6)}, {1, 0.0}};
      sp.upper = [](const Ctx& c) {
        return std::vector<std::pair<int, double>>{{0, std::log(std::max(2e-6, 0.02 * c.rec.v_max_abs))}, {1, 1.0}};
      };
      s.push_back(sp);
    }
    {
      // Not an effect: the Stribeck exponent delta of exp(-|v/vs|^delta) (friction.stribeck_exponent,
      // shared by a static friction's hump and a stribeck_friction effect). 2 (Gaussian) is a
      // convention, not a law: measured Stribeck curves are fitted with delta from about 0.5 to 2
      // (Armstrong-Helouvry, Dupont & Canudas de Wit 1994, sec. 2.1). Held at 2, a hump of another
      // shape is patched by viscous friction, presliding or a level out of tolerance. Bounded to
      // [1, 3], a factor 2 around the convention: wider, the exponent of a weakly seen hump would
      // stand in for other terms (a delta near 0 flattens the hump into a constant).
      Spec sp;
      sp.name = kExponent;
      sp.dim = 1;
      sp.lower = {{0, 1.0}};
      sp.upper = [](const Ctx&) { return std::vector<std::pair<int, double>>{{0, 3.0}}; };
      s.push_back(sp);
    }
    {
      // Not an effect: the model-form offset of a direction asymmetry of the friction, carried
      // by constant_force, F = bound * tanh(theta) within +-bound.
      Spec sp;
      sp.name = kOffset;
      sp.dim = 1;
      s.push_back(sp);
    }
    return s;
  }();
  return all;
}

const Spec& spec(const std::string& name) {
  for (const Spec& s : specs())
    if (s.name == name) return s;
  throw std::invalid_argument("unknown effect '" + name + "'");
}

struct Block {
  const Spec* spec;
  int offset;
};

plant::PlantParams with_theta(const plant::PlantParams& base, const std::vector<Block>& blocks, const double* th,
                              const Ctx& c) {
  plant::PlantParams p = base;
  for (const Block& b : blocks) {
    const Theta t(th + b.offset, th + b.offset + b.spec->dim);
    if (b.spec->name == kSmoothing) {
      p.friction.static_smoothing_velocity = std::exp(t[0]);
      p.friction.static_smoothing_shape = t[1];
    } else if (b.spec->name == kExponent) {
      p.friction.stribeck_exponent = t[0];
    } else if (b.spec->name == kOffset) {
      plant::set_effect(p.effects, Effect{"constant_force", {{"force", c.offset_bound * std::tanh(t[0])}}});
    } else {
      plant::set_effect(p.effects, b.spec->to_effect(t, c));
    }
  }
  return p;
}

struct ResidualFunctor {
  const Record* rec;
  const plant::PlantParams* base;
  std::vector<Block> blocks;
  const Ctx* ctx;
  const std::vector<double>* weights;  // per point, nullptr: all 1
  bool operator()(double const* const* params, double* residuals) const {
    const plant::PlantParams p = with_theta(*base, blocks, params[0], *ctx);
    const Eigen::VectorXd r = force_residual(*rec, p);
    for (long i = 0; i < r.size(); ++i) {
      if (!std::isfinite(r[i])) return false;
      residuals[i] = weights ? (*weights)[static_cast<std::size_t>(i)] * r[i] : r[i];
    }
    return true;
  }
};

struct Solved {
  Theta theta;
  double rss{std::numeric_limits<double>::infinity()};
  bool converged{false};
};

Solved solve(const Record& rec, const plant::PlantParams& base, const std::vector<Block>& blocks, Theta theta,
             const Ctx& ctx, int max_iterations, const std::vector<double>* weights = nullptr) {
  const int dim = static_cast<int>(theta.size());
  auto* functor = new ResidualFunctor{&rec, &base, blocks, &ctx, weights};
  auto* cost = new ceres::DynamicNumericDiffCostFunction<ResidualFunctor, ceres::FORWARD>(functor);
  cost->AddParameterBlock(dim);
  cost->SetNumResiduals(static_cast<int>(rec.bank.tau.size()));
  ceres::Problem problem;
  problem.AddResidualBlock(cost, nullptr, theta.data());
  std::vector<int> fixed;
  for (const Block& b : blocks) {
    for (int f : b.spec->fixed) fixed.push_back(b.offset + f);
    for (auto [i, v] : b.spec->lower) problem.SetParameterLowerBound(theta.data(), b.offset + i, v);
    if (b.spec->upper)
      for (auto [i, v] : b.spec->upper(ctx)) problem.SetParameterUpperBound(theta.data(), b.offset + i, v);
  }
  if (!fixed.empty()) {
    if (static_cast<int>(fixed.size()) == dim) {
      problem.SetParameterBlockConstant(theta.data());
    } else {
      problem.SetManifold(theta.data(), new ceres::SubsetManifold(dim, fixed));
    }
  }
  // Ceres reports a failed evaluation (a NaN residual) through glog on stderr at level ERROR,
  // with "Logging before InitGoogleLogging()": the tools promise one line on stderr, and the
  // solver's outcome is read from its summary here. Only a fatal glog message is shown.
  static const bool glog_quiet = (FLAGS_minloglevel = google::GLOG_FATAL, true);
  (void)glog_quiet;
  ceres::Solver::Options opt;
  opt.max_num_iterations = max_iterations;
  opt.linear_solver_type = ceres::DENSE_QR;
  opt.logging_type = ceres::SILENT;
  opt.minimizer_progress_to_stdout = false;
  opt.num_threads = 1;
  // Ctrl-C ends the fit within an iteration (ctx.stop, interrupt.hpp).
  struct StopOnInterrupt : ceres::IterationCallback {
    explicit StopOnInterrupt(const interrupt::StopToken& t) : token(t) {}
    ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
      return token.stop_requested() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
    }
    const interrupt::StopToken& token;
  } stop(ctx.stop);
  opt.callbacks.push_back(&stop);
  ceres::Solver::Summary sum;
  ceres::Solve(opt, &problem, &sum);
  ctx.stop.check();
  Solved out;
  out.theta = theta;
  out.rss = 2.0 * sum.final_cost;
  out.converged = sum.termination_type == ceres::CONVERGENCE;
  if (!std::isfinite(out.rss)) out.rss = std::numeric_limits<double>::infinity();
  return out;
}

}  // namespace

double bic(const Eigen::VectorXd& r, int k, long n_active) {
  const double n = static_cast<double>(n_active > 0 ? n_active : r.size());
  const double rss = std::max(r.squaredNorm(), 1e-300);
  return n * std::log(rss / n) + k * std::log(n);
}

namespace {

// A scanned parameter (held by Ceres, e.g. the contact position): golden-section search between
// the neighbouring distinct start values of the best one, refitting the others at each probe;
// `best` becomes the result when it fits better.
void refine_scanned(const Record& rec, const plant::PlantParams& model, const std::vector<Block>& blocks, const Spec& s,
                    const std::vector<Theta>& starts, const Ctx& ctx, Solved& best) {
  const int f = s.fixed.front();
  std::vector<double> grid;
  for (const Theta& t : starts) grid.push_back(t[static_cast<std::size_t>(f)]);
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());  // starts that share a value (grinding)
  const auto it = std::lower_bound(grid.begin(), grid.end(), best.theta[static_cast<std::size_t>(f)]);
  const std::size_t i = static_cast<std::size_t>(it - grid.begin());
  double lo = grid[i > 0 ? i - 1 : 0], hi = grid[std::min(i + 1, grid.size() - 1)];
  const auto probe = [&](double v) {
    Theta t = best.theta;
    t[static_cast<std::size_t>(f)] = v;
    return solve(rec, model, blocks, t, ctx, 10);
  };
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = hi - g * (hi - lo), b = lo + g * (hi - lo);
  Solved sa = probe(a), sb = probe(b);
  for (int k = 0; k < 12; ++k) {
    if (sa.rss < sb.rss) {
      hi = b;
      b = a;
      sb = sa;
      a = hi - g * (hi - lo);
      sa = probe(a);
    } else {
      lo = a;
      a = b;
      sa = sb;
      b = lo + g * (hi - lo);
      sb = probe(b);
    }
  }
  const Solved& cand = sa.rss < sb.rss ? sa : sb;
  if (cand.rss < best.rss) best = solve(rec, model, blocks, cand.theta, ctx, 100);
}

}  // namespace

CandidateFit fit_candidate(const Record& rec, const plant::PlantParams& model, const std::string& name,
                           const Eigen::VectorXd& residual0, const interrupt::StopToken& stop) {
  const Spec& s = spec(name);
  const Ctx ctx{rec, model, &residual0, x_mean_of(rec), 0.0, stop};
  const std::vector<Block> blocks{{&s, 0}};
  std::vector<Theta> starts = s.starts(ctx);
  CandidateFit out;
  out.parameters = s.dim;
  if (starts.empty()) {
    out.effect = {name, {}};
    out.rss = residual0.squaredNorm();
    out.bic = bic(residual0, 0, rec.active_points());
    out.score = -std::numeric_limits<double>::infinity();
    return out;
  }
  // Stage 1: a few iterations from every start; stage 2: the best two to convergence.
  std::vector<Solved> first;
  for (const Theta& t : starts) first.push_back(solve(rec, model, blocks, t, ctx, starts.size() >= 4 ? 6 : 50));
  std::sort(first.begin(), first.end(), [](const Solved& a, const Solved& b) { return a.rss < b.rss; });
  Solved best = first.front();
  if (starts.size() >= 4 || !best.converged) {
    best.rss = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < first.size() && i < 2; ++i) {
      const Solved s2 = solve(rec, model, blocks, first[i].theta, ctx, 50);
      if (s2.rss < best.rss) best = s2;
    }
  }
  if (s.alternatives) {
    for (const Theta& alt : s.alternatives(best.theta)) {
      const Solved a = solve(rec, model, blocks, alt, ctx, 100);
      if (a.rss <= best.rss * (1.0 + 1e-3)) best = a;
    }
  }
  if (s.fixed.size() == 1 && starts.size() > 2) refine_scanned(rec, model, blocks, s, starts, ctx, best);
  out.effect = s.to_effect(best.theta, ctx);
  plant::PlantParams p = model;
  plant::set_effect(p.effects, out.effect);
  const Eigen::VectorXd r = force_residual(rec, p);
  out.rss = r.squaredNorm();
  out.bic = bic(r, s.dim, rec.active_points());
  out.score = bic(residual0, 0, rec.active_points()) - out.bic;
  out.converged = best.converged;
  if (!std::isfinite(out.score)) out.score = -std::numeric_limits<double>::infinity();
  return out;
}

bool has_coulomb_term(const plant::PlantParams& model) {
  // presliding makes a static friction LuGre, which has no eps
  return (model.friction.model == plant::FrictionModel::kStatic && !model.effects.presliding.enabled) ||
         model.effects.coulomb_friction.enabled || model.effects.stribeck_friction.enabled;
}

bool has_stribeck_hump(const plant::PlantParams& model) {
  // a static friction's hump, also once presliding made it LuGre (its g(v) has the same
  // exponent); a scenario's own LuGre friction is a dynamic model its engineer identified whole
  const plant::FrictionParams& f = model.friction;
  const bool static_base = f.model == plant::FrictionModel::kStatic || model.effects.presliding.enabled;
  return (static_base && f.static_force > f.coulomb_force) || model.effects.stribeck_friction.enabled;
}

int FreeSet::parameters(const plant::PlantParams& model) const {
  int k = 0;
  for (const std::string& n : effects) k += spec(n).dim;
  if (form && has_coulomb_term(model)) k += spec(kSmoothing).dim;
  if (form && exponent && has_stribeck_hump(model)) k += spec(kExponent).dim;
  return k;
}

namespace {

// The blocks and start vector of a joint fit of `free` on `model`.
std::pair<std::vector<Block>, Theta> joint_blocks(const plant::PlantParams& model, const FreeSet& free,
                                                  const Ctx& ctx) {
  std::vector<Block> blocks;
  Theta theta;
  for (const std::string& name : free.effects) {
    const Spec& s = spec(name);
    blocks.push_back({&s, static_cast<int>(theta.size())});
    Effect e{name, {}};
    for (const Effect& en : plant::enabled_effects(model.effects))
      if (en.name == name) e = en;
    const Theta t = s.from_effect(e, ctx);
    theta.insert(theta.end(), t.begin(), t.end());
  }
  if (free.form && has_coulomb_term(model)) {
    blocks.push_back({&spec(kSmoothing), static_cast<int>(theta.size())});
    theta.push_back(std::log(model.friction.static_smoothing_velocity));
    theta.push_back(model.friction.static_smoothing_shape);
  }
  if (free.form && free.exponent && has_stribeck_hump(model)) {
    blocks.push_back({&spec(kExponent), static_cast<int>(theta.size())});
    theta.push_back(model.friction.stribeck_exponent);
  }
  if (free.offset_bound > 0.0) {
    blocks.push_back({&spec(kOffset), static_cast<int>(theta.size())});
    const double f = model.effects.constant_force.enabled ? model.effects.constant_force.force : 0.0;
    theta.push_back(std::atanh(std::clamp(f / free.offset_bound, -0.999, 0.999)));
  }
  return {blocks, theta};
}

// Ceres keeps a bounded parameter inside its bounds only if it starts there.
void clamp_to_bounds(Theta& theta, const std::vector<Block>& blocks, const Ctx& ctx) {
  for (const Block& b : blocks) {
    for (auto [i, v] : b.spec->lower) theta[b.offset + i] = std::max(theta[b.offset + i], v);
    if (b.spec->upper)
      for (auto [i, v] : b.spec->upper(ctx)) theta[b.offset + i] = std::min(theta[b.offset + i], v);
  }
}

// The start of the smoothed sign's (eps, b), if they are free: the best of the given start and a
// grid, eps geometric over its bounds (8 values), b in {0, 1/2, 1}, the other parameters held.
// From a small eps the least-squares problem is flat in eps: the stick windows are left out
// (mask_stiction) and above them tanh(v/eps) is saturated, so a real transition of 100 um/s or
// more is not found from the default 10 um/s (the solver drifts to the bound instead).
template <class Rss>
void start_form(const Record& rec, const plant::PlantParams& model, const std::vector<Block>& blocks, Theta& theta,
                const Ctx& ctx, const Rss& rss_of) {
  const Block* form = nullptr;
  for (const Block& b : blocks)
    if (b.spec->name == kSmoothing) form = &b;
  if (!form) return;
  const int o = form->offset;
  const double lo = form->spec->lower[0].second, hi = form->spec->upper(ctx)[0].second;
  const auto rss_at = [&](double ln_eps, double b) {
    Theta t = theta;
    t[o] = ln_eps;
    t[o + 1] = b;
    const Eigen::VectorXd r = force_residual(rec, with_theta(model, blocks, t.data(), ctx));
    return r.allFinite() ? rss_of(r) : std::numeric_limits<double>::infinity();
  };
  double best = rss_at(theta[o], theta[o + 1]), best_eps = theta[o], best_b = theta[o + 1];
  constexpr int kEps = 8;
  for (int i = 0; i < kEps; ++i) {
    const double ln_eps = lo + (hi - lo) * i / (kEps - 1);
    for (double b : {0.0, 0.5, 1.0}) {
      const double s = rss_at(ln_eps, b);
      if (s < best) best = s, best_eps = ln_eps, best_b = b;
    }
  }
  theta[o] = best_eps;
  theta[o + 1] = best_b;
}

}  // namespace

JointFit fit_jointly(const Record& rec, const plant::PlantParams& model, const FreeSet& free,
                     const std::vector<double>* weights, int max_iterations, const interrupt::StopToken& stop) {
  const Eigen::VectorXd r0 = force_residual(rec, model);
  const Ctx ctx{rec, model, &r0, x_mean_of(rec), free.offset_bound, stop};
  auto [blocks, theta] = joint_blocks(model, free, ctx);
  JointFit out;
  out.params = model;
  out.parameters = free.parameters(model);
  const auto weighted_rss = [&](const Eigen::VectorXd& r) {
    if (!weights) return r.squaredNorm();
    double s = 0.0;
    for (long i = 0; i < r.size(); ++i) s += (*weights)[static_cast<std::size_t>(i)] * r[i] * r[i];
    return s;
  };
  out.rss = weighted_rss(r0);
  out.converged = true;
  if (blocks.empty()) return out;
  clamp_to_bounds(theta, blocks, ctx);
  start_form(rec, model, blocks, theta, ctx, weighted_rss);
  const Solved sol = solve(rec, model, blocks, theta, ctx, max_iterations, weights);
  if (!(sol.rss < out.rss)) return out;
  out.params = with_theta(model, blocks, sol.theta.data(), ctx);
  out.rss = sol.rss;
  out.converged = sol.converged;
  return out;
}

std::vector<double> cross_validate(const Record& rec, const plant::PlantParams& model, const FreeSet& free, int folds,
                                   const interrupt::StopToken& stop) {
  std::vector<long> active;
  for (long i = 0; i < static_cast<long>(rec.bank.tau.size()); ++i)
    if (rec.masked.empty() || !rec.masked[static_cast<std::size_t>(i)]) active.push_back(i);
  std::vector<double> out(static_cast<std::size_t>(folds), 0.0);
  const long n = static_cast<long>(active.size());
  for (int f = 0; f < folds; ++f) {
    const long lo = n * f / folds, hi = n * (f + 1) / folds;
    std::vector<double> w(rec.bank.tau.size(), 0.0);
    for (long a = 0; a < n; ++a)
      if (a < lo || a >= hi) w[static_cast<std::size_t>(active[a])] = 1.0;
    // a warm start from the full fit converges in a few iterations
    const JointFit jf = fit_jointly(rec, model, free, &w, 20, stop);
    const Eigen::VectorXd r = force_residual(rec, jf.params);
    for (long a = lo; a < hi; ++a) out[static_cast<std::size_t>(f)] += r[active[a]] * r[active[a]];
  }
  return out;
}

double& form_parameter(plant::PlantParams& p, const std::string& key) {
  if (key == "coulomb_transition_velocity") return p.friction.static_smoothing_velocity;
  if (key == "coulomb_transition_shape") return p.friction.static_smoothing_shape;
  if (key == "stribeck_exponent") return p.friction.stribeck_exponent;
  if (key == "direction_asymmetry") return p.effects.constant_force.force;
  throw std::invalid_argument("form_parameter: unknown model-form parameter '" + key + "'");
}

std::map<std::string, std::map<std::string, double>> confidence_intervals(const Record& rec,
                                                                          const plant::PlantParams& fitted,
                                                                          const std::vector<std::string>& effects,
                                                                          const std::vector<std::string>& form) {
  std::map<std::string, std::map<std::string, double>> out;
  std::vector<std::pair<std::string, std::string>> keys;
  std::vector<Effect> named;
  for (const std::string& name : effects)
    for (const Effect& e : plant::enabled_effects(fitted.effects))
      if (e.name == name) {
        named.push_back(e);
        for (const auto& [k, v] : e.parameters) keys.emplace_back(name, k);
      }
  for (const std::string& key : form) keys.emplace_back("model_form", key);
  if (keys.empty()) return out;
  const Eigen::VectorXd r0 = force_residual(rec, fitted);
  const long n = rec.active_points();
  const long k = static_cast<long>(keys.size());
  Eigen::MatrixXd J(r0.size(), k);
  for (long c = 0; c < k; ++c) {
    const auto& [name, key] = keys[static_cast<std::size_t>(c)];
    const bool is_form = name == "model_form";
    Effect e;
    for (const Effect& x : named)
      if (x.name == name) e = x;
    plant::PlantParams base = fitted;
    const double v = is_form ? form_parameter(base, key) : e.parameters.at(key);
    // a phase moves by 1e-4 rad; anything else by 1e-5 of itself (or of a typical size)
    const double h = key.find("phase") != std::string::npos ? 1e-4 : 1e-5 * std::max(std::abs(v), 1e-3);
    Eigen::VectorXd rp, rm;
    for (int s : {1, -1}) {
      plant::PlantParams p = fitted;
      if (is_form) {
        form_parameter(p, key) = v + s * h;
      } else {
        Effect moved = e;
        moved.parameters[key] = v + s * h;
        plant::set_effect(p.effects, moved);
      }
      (s > 0 ? rp : rm) = force_residual(rec, p);
    }
    J.col(c) = (rp - rm) / (2 * h);
  }
  force_residual(rec, fitted);  // leaves the cache on the fitted model
  const double s2 = r0.squaredNorm() / static_cast<double>(std::max(1L, n - k));
  const Eigen::MatrixXd JtJ = J.transpose() * J;
  // scaled pseudo-inverse: columns of very different units
  Eigen::VectorXd d(k);
  for (long c = 0; c < k; ++c) d[c] = JtJ(c, c) > 0 ? 1.0 / std::sqrt(JtJ(c, c)) : 0.0;
  const Eigen::MatrixXd S = d.asDiagonal() * JtJ * d.asDiagonal();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(S, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd sv = svd.singularValues();
  Eigen::VectorXd inv(k);
  for (long c = 0; c < k; ++c) inv[c] = sv[c] > 1e-10 * sv[0] ? 1.0 / sv[c] : 0.0;
  const Eigen::MatrixXd P = svd.matrixV() * inv.asDiagonal() * svd.matrixU().transpose();
  for (long c = 0; c < k; ++c) {
    const auto& [name, key] = keys[static_cast<std::size_t>(c)];
    const double var = s2 * d[c] * d[c] * P(c, c);
    out[name][key] =
        d[c] > 0 && var > 0 && std::isfinite(var) ? 1.96 * std::sqrt(var) : std::numeric_limits<double>::quiet_NaN();
  }
  return out;
}

Effect canonical(const Effect& e) {
  if (e.name != "cogging_ripple") return e;
  const auto& p = e.parameters;
  const double a1 = std::abs(p.at("cogging_amplitude")), a3 = std::abs(p.at("cogging_third"));
  if (!(a3 > 0.0) || a1 >= 0.1 * a3) return e;
  return Effect{e.name,
                {{"pitch", p.at("pitch") / 3.0},
                 {"cogging_amplitude", a3},
                 {"cogging_phase", p.at("cogging_third_phase")},
                 {"cogging_third", 0.0},
                 {"cogging_third_phase", 0.0}}};
}

double mean_position(const Record& rec) { return x_mean_of(rec); }

std::optional<Effect> simpler_form(const Effect& e, double x_mean) {
  const auto& q = e.parameters;
  if (e.name == "stribeck_friction") return Effect{"coulomb_friction", {{"coulomb_force", q.at("coulomb_force")}}};
  if (e.name == "spring_force")
    return Effect{"constant_force", {{"force", q.at("stiffness") * (x_mean - q.at("rest_position"))}}};
  if (e.name == "cogging_ripple") {
    const Effect c = canonical(e);
    if (c.parameters != e.parameters) return c;
  }
  return std::nullopt;
}

std::pair<std::string, std::vector<double>> effect_regressor(const Record& rec, const Effect& e) {
  const auto& b = rec.bank;
  const auto& m = rec.motion;
  std::vector<double> out(b.tau.size());
  const auto at = [&](std::size_t i) { return static_cast<std::size_t>(b.nearest[i]); };
  const std::string& n = e.name;
  if (n == "coulomb_friction" || n == "viscous_friction" || n == "stribeck_friction" || n == "presliding") {
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = m.v[at(i)] * 1e3;
    return {"velocity [mm/s]", out};
  }
  if (is_ripple(n)) {
    const double p = e.parameters.at("pitch");
    for (std::size_t i = 0; i < out.size(); ++i) {
      const double q = std::fmod(m.x[at(i)], p);
      out[i] = (q < 0 ? q + p : q) * 1e3;
    }
    return {"position modulo the pitch [mm]", out};
  }
  if (n == "grinding_force" || n == "spring_force") {
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = m.x[at(i)] * 1e3;
    return {"position [mm]", out};
  }
  if (n == "mass_error") return {"filtered acceleration [m/s^2]", b.accel};
  if (n == "input_delay") {
    const double d = rec.period;
    const Eigen::VectorXd ahead = apply_delayed(b, rec.data->t, rec.input, -d);
    const Eigen::VectorXd behind = apply_delayed(b, rec.data->t, rec.input, d);
    for (std::size_t i = 0; i < out.size(); ++i)
      out[i] = (ahead[static_cast<long>(i)] - behind[static_cast<long>(i)]) / (2 * d);
    return {"input rate [input unit/s]", out};
  }
  return {"t [s]", b.tau};
}

}  // namespace feeddrive::fit
