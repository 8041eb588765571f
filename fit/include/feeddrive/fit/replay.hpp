#pragma once
// The gap metric and where the gap concentrates (docs/fit.md, "Gap" and "Localisation").
//
// Replay: the record is cut into windows of W seconds. Each window is simulated with the model
// (the CVODE plant of plant.hpp, ideal sensor) from the measured state at its start (x^, v^ of
// signals.hpp; z and Fg integrated along the measured motion, model.hpp) under the measured input
// held over each sample interval. The gap is the RMS over all samples of x_sim - x_measured [m]:
//     gap = sqrt( sum_windows sum_k (x_sim(t_k) - x_k)^2 / N ).
// Restarting every window keeps it meaningful for a drive whose open-loop position drifts.
// The force measure is the RMS of the filtered force residual r_i of model.hpp [N].

#include <string>
#include <vector>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/fit/model.hpp"
#include "feeddrive/plant/params.hpp"

namespace feeddrive::fit {

struct Replay {
  double gap{0.0};            ///< RMS position error [m]
  std::vector<double> x_sim;  ///< replayed position at every sample [m]
  std::vector<double> error;  ///< x_sim - x at every sample [m] (0 at window starts)
};

/// The replay window W [s] of a `window` setting: window itself, or for 0 the default: 0.1 s (at
/// least 20 samples).
double window_length(const Record& rec, double window);

/// window: W [s]; 0 picks the default (window_length).
Replay replay(const Record& rec, const plant::PlantParams& model, double window = 0.0,
              const interrupt::StopToken& stop = {});

/// RMS of a residual vector over n_active points (0: all).
double rms(const Eigen::VectorXd& r, long n_active = 0);

/// One bin of the localisation: a share of the squared force residual and of the samples.
struct Bin {
  std::string label;
  long points{0};
  double force_rms{0.0};      ///< RMS filtered force residual in the bin [N]
  double share{0.0};          ///< fraction of the total squared residual
  double concentration{0.0};  ///< share / fraction of the points (1 = uniform)
  double gap{0.0};            ///< RMS replay position error of the samples in the bin [m]
};
struct Localisation {
  std::vector<Bin> time, velocity, acceleration, position;
  std::string summary;  ///< one sentence: where the gap concentrates
};

Localisation localise(const Record& rec, const Eigen::VectorXd& residual, const Replay& rp);

}  // namespace feeddrive::fit
