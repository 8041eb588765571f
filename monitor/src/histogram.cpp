#include "feeddrive/monitor/histogram.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace feeddrive::monitor {

Histogram histogram(const std::vector<double>& v, double bin_us, int bins) {
  if (!(bin_us > 0.0) || bins <= 0) throw std::invalid_argument("histogram: bin width and count must be > 0");
  Histogram h;
  h.bin_us = bin_us;
  h.counts.assign(static_cast<std::size_t>(bins), 0);
  for (const double x : v) {
    if (std::isnan(x)) continue;
    ++h.samples;
    const double i = std::floor(std::max(x, 0.0) / bin_us);
    if (i >= bins) {
      ++h.overflow;
    } else {
      ++h.counts[static_cast<std::size_t>(i)];
    }
  }
  return h;
}

std::vector<double> period_start_lateness(const std::vector<double>& recv_us, double period_us) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> late(recv_us.size(), nan);
  std::vector<double> offset;
  for (std::size_t k = 1; k < recv_us.size(); ++k)
    if (!std::isnan(recv_us[k])) offset.push_back(recv_us[k] - static_cast<double>(k) * period_us);
  if (offset.empty()) return late;
  // The origin is the 0.1 % quantile of the offsets, not their minimum: a receive time is the
  // kernel's wall-clock stamp moved onto the monotonic clock, and one stamp taken across a
  // clock adjustment would otherwise shift every other state's lateness.
  const std::size_t q = offset.size() / 1000;
  std::nth_element(offset.begin(), offset.begin() + static_cast<std::ptrdiff_t>(q), offset.end());
  const double origin = offset[q];
  for (std::size_t k = 1; k < recv_us.size(); ++k)
    if (!std::isnan(recv_us[k])) late[k] = recv_us[k] - static_cast<double>(k) * period_us - origin;
  return late;
}

std::string histograms_csv(const std::vector<std::string>& names, const std::vector<Histogram>& h) {
  std::string out = "bin_start_us";
  for (const auto& n : names) out += "," + n;
  out += "\n";
  const std::size_t bins = h.empty() ? 0 : h.front().counts.size();
  char buf[64];
  for (std::size_t i = 0; i < bins; ++i) {
    std::snprintf(buf, sizeof buf, "%g", static_cast<double>(i) * h.front().bin_us);
    out += buf;
    for (const Histogram& x : h) out += "," + std::to_string(i < x.counts.size() ? x.counts[i] : 0);
    out += "\n";
  }
  return out;
}

}  // namespace feeddrive::monitor
