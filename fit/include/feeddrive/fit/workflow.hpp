#pragma once
// The model-discrepancy loop of feeddrive-fit (docs/fit.md):
//   replay -> localise -> rank every candidate effect -> add the winner (refit all added effects
//   jointly) -> confirm by replay -> repeat, until no candidate scores above the threshold, the
//   winner does not shrink the replay gap, or max_effects effects are in.
// Pure computation: no files are read or written here.

#include <functional>
#include <string>
#include <vector>

#include "feeddrive/fit/identify.hpp"
#include "feeddrive/fit/model.hpp"
#include "feeddrive/fit/replay.hpp"

namespace feeddrive::fit {

struct FitOptions {
  int max_effects{4};
  double score_threshold{10.0};     ///< least BIC score of a significant effect
  double min_gap_reduction{0.05};   ///< the replay gap must shrink by at least this fraction
  double replay_window{0.0};        ///< W [s] of the replay (0: default)
  RecordOptions record;
};

struct StepResult {
  std::vector<CandidateFit> ranking;   ///< best first
  Localisation localisation;           ///< of the model before the step
  bool accepted{false};
  std::string verdict;                 ///< one line: what was decided and why
  Effect effect;                       ///< the winner as fitted alone
  double score{0.0};
  double gap_before{0.0}, gap_after{0.0};              ///< replay gap [m]
  double force_rms_before{0.0}, force_rms_after{0.0};  ///< filtered force residual RMS [N]
  Eigen::VectorXd residual_before, residual_after;     ///< at the filter points [N]
};

struct FitResult {
  plant::PlantParams initial, fitted;
  Replay replay_initial, replay_final;
  double force_rms_initial{0.0}, force_rms_final{0.0};
  std::vector<StepResult> steps;       ///< every step, the last one may be rejected
  std::vector<Effect> effects;         ///< the added effects with their final (jointly refitted) parameters
  Localisation final_localisation;
  std::string conclusion;
};

using Log = std::function<void(const std::string&)>;
FitResult run_fit(const Record& rec, const plant::PlantParams& model, const FitOptions& opt, const Log& log = {});

}  // namespace feeddrive::fit
