#pragma once
// Latency histograms of a run (summary.json "latency_histogram_us", latency_histogram.png).
// Pure functions of the samples: fixed-width bins from 0, the samples beyond the last bin
// counted apart (overflow), negative samples in the first bin.

#include <cstdint>
#include <string>
#include <vector>

namespace feeddrive::monitor {

struct Histogram {
  double bin_us{0.0};                 ///< bin width [us]; bin i holds [i*bin_us, (i+1)*bin_us)
  std::vector<std::int64_t> counts;   ///< one per bin
  std::int64_t overflow{0};           ///< samples >= counts.size() * bin_us
  std::int64_t samples{0};
};

/// Histogram of `v` [us] with `bins` bins of `bin_us` (> 0). NaN samples are skipped.
Histogram histogram(const std::vector<double>& v, double bin_us, int bins);

/// Period-start lateness [us] of real-time states: for the receive times recv_us[k] of state k
/// (NaN: not received) and the period T [us], recv_us[k] - k*T minus the 0.1 % quantile of
/// those values, so the earliest states are 0 late (one clock, no offset to know; a state
/// stamped early is negative and falls in the first bin). NaN where not received, and
/// for state 0, which goes out before the clock starts (the start handshake).
std::vector<double> period_start_lateness(const std::vector<double>& recv_us, double period_us);

/// CSV of histograms side by side: "bin_start_us,<name 1>,<name 2>,...", one row per bin.
std::string histograms_csv(const std::vector<std::string>& names, const std::vector<Histogram>& h);

}  // namespace feeddrive::monitor
