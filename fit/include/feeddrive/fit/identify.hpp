#pragma once
// Naming the missing effect (docs/fit.md, "Naming the effect").
//
// Every effect of the vocabulary (plant/effects.hpp) is a candidate. A candidate is fitted by
// nonlinear least squares (Ceres, Levenberg-Marquardt, central-difference Jacobian) of the
// filtered force residual of model.hpp over its parameters, from several starts (a pitch
// periodogram for the ripples, grids for the scale parameters). It is scored by the Bayesian
// information criterion of the residual at the filter points, which are independent:
//     BIC = n ln(RSS/n) + k ln(n),     score = BIC(model) - BIC(model + candidate)
// (Schwarz 1978; a score above 10 is "very strong" evidence, Kass & Raftery 1995).

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/fit/model.hpp"
#include "feeddrive/plant/effects.hpp"
#include "feeddrive/plant/params.hpp"

namespace feeddrive::fit {

/// An effect of the vocabulary with its parameters (plant/effects.hpp: names, set_effect,
/// enabled_effects).
using Effect = plant::NamedEffect;

/// Why a candidate was not named (for the suggestion of what record would settle it).
enum class Reason { kNone, kPrerequisite, kImplausible, kBelowThreshold, kNotConfirmed, kNoGapReduction, kInvalid };

struct CandidateFit {
  Effect effect;      ///< as fitted jointly with the effects already added
  int parameters{0};  ///< k of the candidate in the BIC
  double rss{0.0};    ///< sum of squared filtered residuals of the joint fit [N^2]
  double bic{0.0};
  double score{0.0};  ///< BIC(model) - BIC(model + candidate, joint fit); > 0 favours the effect
  bool converged{false};
  std::string passed_over;       ///< empty if eligible; else why not (prerequisite, implausible values, ...)
  plant::PlantParams joint;      ///< the model plus the candidate, every free parameter jointly refitted
  double seconds{0.0};           ///< wall time of its fits
  Reason reason{Reason::kNone};  ///< why it was passed over (kNone: eligible)
  /// Named although it fails a plausibility limit, because the limit lies within the 95 %
  /// confidence interval of the fitted value (docs/fit.md, "Tentative"): the caveat says which.
  bool tentative{false};
  std::string caveat;
  /// A swap move of its joint fit: an effect already in the model that the refit turned into a
  /// simpler one, e.g. "stribeck_friction -> coulomb_friction" (docs/fit.md, "Swap moves").
  std::string swap;
  std::vector<std::string> free_effects;  ///< the effects its joint fit refitted (with any swap)
};

/// 95 % confidence half-widths of every parameter of the named `effects` of `fitted`: the
/// Gauss-Newton covariance s^2 (J^T J)^+ of the least-squares fit (Seber & Wild, Nonlinear
/// Regression, 1989, sec. 5.1), s^2 = RSS/(n - k) over the n independent filter points, J the
/// central-difference Jacobian of the filtered residual in the vocabulary's own parameters
/// (pseudo-inverse: a phase of a vanishing amplitude is undetermined and gets NaN).
/// `form`: the model-form parameters that were fitted too (form_parameter's keys), in the same
/// covariance (they correlate with the effects'), returned under "model_form".
/// Returns {effect: {parameter: 1.96 sigma}}.
std::map<std::string, std::map<std::string, double>> confidence_intervals(const Record& rec,
                                                                          const plant::PlantParams& fitted,
                                                                          const std::vector<std::string>& effects,
                                                                          const std::vector<std::string>& form = {});
/// The model-form parameters by their findings.json keys: the Coulomb transition velocity eps
/// [m/s] and shape b [-] of sgn_eps, the Stribeck exponent delta [-], and the friction's direction
/// asymmetry [N] (carried as constant_force when that is not named).
double& form_parameter(plant::PlantParams& p, const std::string& key);

/// BIC of a residual vector with k parameters over n_active points (0: all of r).
double bic(const Eigen::VectorXd& r, int k, long n_active = 0);

/// Fits one candidate added to `model` alone (the model's own parameters held), by nonlinear
/// least squares from the candidate's starts; `residual0` is force_residual(rec, model). The
/// start of the joint fit.
CandidateFit fit_candidate(const Record& rec, const plant::PlantParams& model, const std::string& name,
                           const Eigen::VectorXd& residual0, const interrupt::StopToken& stop = {});

/// What a joint fit refits: the named effects (enabled in the model) and, if `form` and the model
/// has a Coulomb-type term (static friction, coulomb_friction or stribeck_friction), the
/// smoothing velocity eps of sgn_eps(v) = tanh(v/eps) (friction.static_smoothing_velocity), a
/// model-form parameter: real friction changes sign over a finite velocity band; and, if the
/// model has a Stribeck hump, its exponent delta in [1, 3] (has_stribeck_hump).
struct FreeSet {
  std::vector<std::string> effects;
  bool form{false};
  /// > 0: also a model-form offset |F| <= offset_bound, carried by constant_force (not named):
  /// a direction asymmetry of the friction, which moving data cannot tell from a constant force.
  double offset_bound{0.0};
  /// With `form`: whether the Stribeck exponent is refitted too (false: held at the model's). The
  /// candidate fits hold it (workflow.cpp, fit_with): a free exponent is a parameter no score
  /// counts, which a stribeck_friction candidate would have and coulomb_friction not.
  bool exponent{true};
  int parameters(const plant::PlantParams& model) const;  ///< k of the BIC
};
bool has_coulomb_term(const plant::PlantParams& model);
/// Whether the model has a Stribeck hump whose exponent delta (friction.stribeck_exponent) a
/// joint fit with `form` refits as model form: a static friction (also once presliding made it
/// LuGre) with static level above Coulomb, or a stribeck_friction effect.
bool has_stribeck_hump(const plant::PlantParams& model);

struct JointFit {
  plant::PlantParams params;  ///< the refitted model
  double rss{0.0};            ///< over the points with weight 1 [N^2]
  int parameters{0};
  bool converged{false};
};
/// Refits every free parameter of `model` jointly (Ceres, Levenberg-Marquardt) starting from its
/// values. `weights` (0 or 1 per filter point, nullptr: all 1) leaves points out of the fit.
JointFit fit_jointly(const Record& rec, const plant::PlantParams& model, const FreeSet& free,
                     const std::vector<double>* weights = nullptr, int max_iterations = 100,
                     const interrupt::StopToken& stop = {});

/// Out-of-sample evidence: the active filter points are cut into `folds` contiguous blocks of
/// time; for each block the free parameters are refitted on the other blocks (warm start from
/// `model`) and the squared residual on the block itself is summed. Returns the per-block sums
/// [N^2] (with nothing free: the model's residual per block).
std::vector<double> cross_validate(const Record& rec, const plant::PlantParams& model, const FreeSet& free,
                                   int folds = 5, const interrupt::StopToken& stop = {});

/// The canonical form of a fitted effect: a cogging ripple whose fundamental is below a tenth
/// of its third harmonic is the ripple of a third of the pitch (its "third harmonic" is its
/// fundamental): sin(6 pi x/p + phi3) = sin(2 pi x/(p/3) + phi3).
Effect canonical(const Effect& e);

/// The simpler effect a joint refit may have turned `e` into (the swap move, docs/fit.md "Swap
/// moves"), if any: a Stribeck curve (its hump gone) -> coulomb_friction at its Coulomb level; a
/// spring (its slope gone) -> the constant_force k (x_mean - x_rest) it exerts over the range; a
/// cogging ripple whose fundamental vanished -> canonical(e), the ripple of its harmonic.
/// Whether the refit did collapse `e` is for the plausibility rules to say.
std::optional<Effect> simpler_form(const Effect& e, double x_mean);
/// The mean measured position of the record [m] (the spring's reference point).
double mean_position(const Record& rec);

/// The x-axis of the plot of the residual against the effect's own regressor, at filter point
/// i: e.g. position modulo the pitch for a ripple, velocity for friction. Returns {label, values}.
std::pair<std::string, std::vector<double>> effect_regressor(const Record& rec, const Effect& e);

}  // namespace feeddrive::fit
