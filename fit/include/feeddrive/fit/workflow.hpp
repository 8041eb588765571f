#pragma once
// The model-discrepancy loop of feeddrive-fit (docs/fit.md, "Naming the effects"): bidirectional
// stepwise selection (Efroymson 1960) with joint refits.
//   0. model form: the Coulomb transition velocity and shape of a static friction model are refitted;
//   1. forward: every candidate whose prerequisites hold (plausibility.hpp) is fitted alone, then
//      jointly with every effect added so far; it is scored by BIC(model) - BIC(model + it);
//      candidates with implausible fitted values are passed over, with the reason;
//   2. the best eligible candidate (fewest parameters among those within 10 of the best score)
//      is added if its score is >= the threshold, it is confirmed out of sample (blocked
//      cross-validation, one-standard-error rule) and it shrinks the replay gap;
//   3. backward: every earlier effect whose removal (the others refitted) costs less than the
//      threshold in BIC is removed, the least costly first;
//   repeat until no candidate is added or max_effects effects are in;
//   4. final confirmation: every named effect must still meet the criteria it entered on (2), with
//      all the others in the model: the removal criterion equals the entry criterion (Efroymson
//      1960; Draper & Smith 1998, sec. 15.2: F-to-remove <= F-to-enter); one that fails them is
//      removed, the weakest first, until all pass.
// Pure computation: no files are read or written here.

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/fit/identify.hpp"
#include "feeddrive/fit/model.hpp"
#include "feeddrive/fit/plausibility.hpp"
#include "feeddrive/fit/replay.hpp"
#include "feeddrive/fit/verdict.hpp"

namespace feeddrive::fit {

struct FitOptions {
  int max_effects{4};
  int cv_folds{5};      ///< blocks of time of the cross-validation
  bool fit_form{true};  ///< refit the Coulomb transition velocity (model form)
  PlausibilityOptions plausibility;
  double score_threshold{10.0};    ///< least BIC score of a significant effect
  double min_gap_reduction{0.05};  ///< the replay gap must shrink by at least this fraction
  double replay_window{0.0};       ///< W [s] of the replay (0: default)
  double stamp_error{0.0};         ///< sigma_t [s] of the record's time stamps, for the noise floor (verdict.hpp)
  interrupt::StopToken stop;       ///< polled by the replays and solves (Ctrl-C in the tool; the default never stops)
  RecordOptions record;
};

struct StepResult {
  std::vector<CandidateFit> ranking;  ///< best first
  Localisation localisation;          ///< of the model before the step
  bool accepted{false};
  std::string verdict;  ///< one line: what was decided and why
  Effect effect;        ///< the winner as fitted jointly when it was added
  double score{0.0};
  /// Out-of-sample evidence of the winner: per block of time, the squared residual [N^2] of the
  /// model without and with it, each refitted on the other blocks.
  std::vector<double> cv_without, cv_with;
  std::vector<std::string> removed;  ///< effects removed by the backward step after the addition
  std::string swap;                  ///< a swap move of this step, e.g. "stribeck_friction -> coulomb_friction"
  std::string caveat;                ///< the winner was named as tentative: why (else empty)
  /// Candidates the record cannot tell from the winner (docs/fit.md, "Ties"), with their evidence.
  std::vector<std::string> ties, tie_notes;
  double gap_before{0.0}, gap_after{0.0};              ///< replay gap [m]
  double force_rms_before{0.0}, force_rms_after{0.0};  ///< filtered force residual RMS [N]
  Eigen::VectorXd residual_before, residual_after;     ///< at the filter points [N]
};

struct FitResult {
  plant::PlantParams initial, fitted;
  Replay replay_initial, replay_final;
  double force_rms_initial{0.0}, force_rms_final{0.0};
  std::vector<StepResult> steps;  ///< every step, the last one may be rejected
  std::vector<Effect> effects;    ///< the added effects with their final (jointly refitted) parameters
  Localisation final_localisation;
  Envelope envelope;                                    ///< what the record spans (plausibility rules)
  double smoothing_initial{0.0}, smoothing_final{0.0};  ///< eps of sgn_eps [m/s], before and after
  double shape_initial{0.0}, shape_final{0.0};          ///< b of sgn_eps [-] (0 tanh, 1 algebraic), before and after
  double exponent_initial{2.0}, exponent_final{2.0};    ///< Stribeck exponent delta [-], before and after
  bool smoothing_fitted{false};                         ///< eps, b or delta was refitted
  /// The model-form offset of a friction direction asymmetry (within kAsymmetryTolerance of the
  /// friction level), carried by constant_force in `fitted` but not named as an effect [N].
  double asymmetry_offset{0.0};
  std::string conclusion;
  NoiseFloor floor;  ///< the sensor's noise floor (verdict.hpp)
  Verdict verdict{Verdict::kUnexplained};
  /// For an unexplained verdict: where the discrepancy is, what it resembles, why each resembling
  /// candidate was not named and what record would settle it (one sentence each).
  std::vector<std::string> unexplained;
  /// 95 % confidence half-widths of every parameter of the named effects (identify.hpp).
  std::map<std::string, std::map<std::string, double>> ci95;
  std::map<std::string, std::string> tentative;  ///< named effects that are tentative -> caveat
  /// Ties of the named effects that no later step resolved: "a or b: the record cannot separate
  /// them; <what would>".
  std::vector<std::string> ties;
  /// Effects named in a step but removed by the final confirmation (stage 4), each "name: why".
  std::vector<std::string> unconfirmed;
};

/// The options against the record (e.g. a replay window of at least 10 sample periods). Throws
/// DataError. run_fit calls it first; feeddrive-fit calls it before the sanity checks.
void check_options(const Record& rec, const FitOptions& opt);

/// The conclusion's model-form part: "; model form: ..." for each refitted form parameter, with
/// its 95 % half-width from r.ci95["model_form"], or "(not identified by this record)" where that
/// exceeds the value or is not finite.
std::string model_form_text(const FitResult& r);

using Log = std::function<void(const std::string&)>;
FitResult run_fit(const Record& rec, const plant::PlantParams& model, const FitOptions& opt, const Log& log = {});

}  // namespace feeddrive::fit
