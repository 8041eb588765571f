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
#include <string>
#include <vector>

#include "feeddrive/fit/model.hpp"
#include "feeddrive/plant/effects.hpp"
#include "feeddrive/plant/params.hpp"

namespace feeddrive::fit {

/// An effect of the vocabulary with its parameters (plant/effects.hpp: names, set_effect,
/// enabled_effects).
using Effect = plant::NamedEffect;

struct CandidateFit {
  Effect effect;
  int parameters{0};        ///< k in the BIC
  double rss{0.0};          ///< sum of squared filtered residuals [N^2]
  double bic{0.0};
  double score{0.0};        ///< BIC(without) - BIC(with); > 0 favours the effect
  bool converged{false};
};

struct IdentifyOptions {
  double score_threshold{10.0};  ///< least score for a significant effect
};

/// BIC of a residual vector with k parameters over n_active points (0: all of r).
double bic(const Eigen::VectorXd& r, int k, long n_active = 0);

/// Fits one candidate added to `model`. `residual0` is force_residual(rec, model).
CandidateFit fit_candidate(const Record& rec, const plant::PlantParams& model, const std::string& name,
                           const Eigen::VectorXd& residual0);

/// Fits every candidate not yet enabled in `model`; sorted by score, best first.
std::vector<CandidateFit> rank_candidates(const Record& rec, const plant::PlantParams& model);

/// Refits the parameters of every enabled effect of `model` jointly; returns the refined model.
plant::PlantParams refine_jointly(const Record& rec, const plant::PlantParams& model);

/// The x-axis of the plot of the residual against the effect's own regressor, at filter point
/// i: e.g. position modulo the pitch for a ripple, velocity for friction. Returns {label, values}.
std::pair<std::string, std::vector<double>> effect_regressor(const Record& rec, const Effect& e);

}  // namespace feeddrive::fit
