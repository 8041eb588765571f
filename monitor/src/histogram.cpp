#include "feeddrive/monitor/histogram.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace feeddrive::monitor {

Histogram::Histogram(double bin_us, int bins) : bin_us_(bin_us) {
  if (!(bin_us > 0.0) || bins <= 0) throw std::invalid_argument("histogram: bin width and count must be > 0");
  counts_.assign(static_cast<std::size_t>(bins), 0);
}

void Histogram::add(double us, std::int64_t count) {
  if (std::isnan(us)) return;
  samples_ += count;
  const double i = std::floor(std::max(us, 0.0) / bin_us_);
  if (i >= static_cast<double>(counts_.size())) {
    overflow_ += count;
  } else {
    counts_[static_cast<std::size_t>(i)] += count;
  }
}

std::string histograms_csv(const std::vector<std::string>& names, const std::vector<Histogram>& h) {
  std::string out = "bin_start_us";
  for (const auto& n : names) out += "," + n;
  out += "\n";
  const std::size_t bins = h.empty() ? 0 : h.front().counts().size();
  char buf[64];
  for (std::size_t i = 0; i < bins; ++i) {
    std::snprintf(buf, sizeof buf, "%g", static_cast<double>(i) * h.front().bin_us());
    out += buf;
    for (const Histogram& x : h) out += "," + std::to_string(i < x.counts().size() ? x.counts()[i] : 0);
    out += "\n";
  }
  return out;
}

}  // namespace feeddrive::monitor
