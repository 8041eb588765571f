#pragma once
// Latency histograms of a run (summary.json "latency_histogram_us", latency_histogram.csv and
// .png), in bounded memory whatever the run's length: samples are binned as they come.

#include <cstdint>
#include <string>
#include <vector>

namespace feeddrive::monitor {

/// Fixed-width bins from 0: bin i holds [i*bin_us, (i+1)*bin_us); negative samples go to the
/// first bin, samples beyond the last bin are counted apart (overflow); NaN is skipped.
class Histogram {
 public:
  /// Throws std::invalid_argument unless bin_us > 0 and bins > 0.
  Histogram(double bin_us, int bins);
  void add(double us, std::int64_t count = 1);
  double bin_us() const { return bin_us_; }
  const std::vector<std::int64_t>& counts() const { return counts_; }
  std::int64_t overflow() const { return overflow_; }
  std::int64_t samples() const { return samples_; }

 private:
  double bin_us_;
  std::vector<std::int64_t> counts_;
  std::int64_t overflow_{0};
  std::int64_t samples_{0};
};

/// CSV of histograms side by side: "bin_start_us,<name 1>,<name 2>,...", one row per bin.
std::string histograms_csv(const std::vector<std::string>& names, const std::vector<Histogram>& h);

}  // namespace feeddrive::monitor
