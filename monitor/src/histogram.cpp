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

LatenessHistogram::LatenessHistogram(double period_us)
    : period_us_(period_us), fine_(static_cast<std::size_t>(std::ceil(16.0 * period_us)) + 1, 0) {}

void LatenessHistogram::add(std::int64_t k, double recv_us) {
  if (k < 1 || std::isnan(recv_us)) return;
  const double offset = recv_us - static_cast<double>(k) * period_us_;
  if (!have_ref_) {
    have_ref_ = true;
    ref_ = offset;
  }
  const double i = std::floor(offset - ref_ + 4.0 * period_us_);
  if (i < 0) {
    ++below_;
  } else if (i >= static_cast<double>(fine_.size())) {
    ++above_;
  } else {
    ++fine_[static_cast<std::size_t>(i)];
  }
}

Histogram LatenessHistogram::result(double bin_us, int bins) const {
  Histogram h(bin_us, bins);
  std::int64_t n = below_ + above_;
  for (const auto c : fine_) n += c;
  if (n == 0) return h;
  // The origin: the fine bin holding the 0.1 % quantile (a state stamped early, e.g. across a
  // clock adjustment, does not shift every other state's lateness). Earlier states count 0 late.
  const std::int64_t rank = n / 1000;
  std::int64_t seen = below_;
  std::size_t origin = 0;
  if (seen <= rank) {
    for (; origin < fine_.size(); ++origin) {
      seen += fine_[origin];
      if (seen > rank) break;
    }
  }
  h.add(0.0, below_);
  for (std::size_t i = 0; i < fine_.size(); ++i)
    if (fine_[i] > 0) h.add(static_cast<double>(i) - static_cast<double>(origin), fine_[i]);
  h.add(1e300, above_);
  return h;
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
