#include "feeddrive/output/plot_reduce.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "feeddrive/output/csv.hpp"

namespace feeddrive::output {

MinMaxReducer::MinMaxReducer(double t0, double t1, std::size_t buckets, std::size_t curves)
    : t0_(t0), scale_(0.0), buckets_(buckets), curves_(curves), e_(buckets * curves) {
  if (buckets == 0 || !(t1 > t0) || !std::isfinite(t1 - t0))
    throw std::invalid_argument("MinMaxReducer: needs buckets > 0 and a finite t1 > t0");
  scale_ = static_cast<double>(buckets) / (t1 - t0);
}

std::size_t MinMaxReducer::bucket_of(double t) const {
  const double b = std::floor((t - t0_) * scale_);
  if (!(b > 0.0)) return 0;  // also NaN
  if (b >= static_cast<double>(buckets_ - 1)) return buckets_ - 1;
  return static_cast<std::size_t>(b);
}

bool MinMaxReducer::has_samples(std::size_t curve) const {
  for (std::size_t b = 0; b < buckets_; ++b)
    if (at(b, curve).n > 0) return true;
  return false;
}

void MinMaxReducer::add(double t, const double* values) {
  Extremes* row = &e_[bucket_of(t) * curves_];
  for (std::size_t c = 0; c < curves_; ++c) {
    const double y = values[c];
    if (!std::isfinite(y)) continue;
    Extremes& x = row[c];
    if (x.n == 0) {
      x = {t, y, t, y, 1};
      continue;
    }
    ++x.n;
    if (y < x.y_min) x.y_min = y, x.t_min = t;
    if (y > x.y_max) x.y_max = y, x.t_max = t;
  }
}

void MinMaxReducer::write_csv(const std::filesystem::path& path, const std::vector<std::string>& names) const {
  if (names.size() != curves_) throw std::logic_error("MinMaxReducer::write_csv: one name per curve");
  std::vector<std::string> header;
  for (const std::string& n : names) {
    header.push_back("t_" + n);
    header.push_back(n);
  }
  CsvWriter out(path, header);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> first(2 * curves_), second(2 * curves_);
  for (std::size_t b = 0; b < buckets_; ++b) {
    bool any = false;
    for (std::size_t c = 0; c < curves_; ++c) {
      const Extremes& x = at(b, c);
      if (x.n == 0) {
        first[2 * c] = first[2 * c + 1] = second[2 * c] = second[2 * c + 1] = nan;
        continue;
      }
      any = true;
      const bool min_first = x.t_min <= x.t_max;
      first[2 * c] = min_first ? x.t_min : x.t_max;
      first[2 * c + 1] = min_first ? x.y_min : x.y_max;
      second[2 * c] = min_first ? x.t_max : x.t_min;
      second[2 * c + 1] = min_first ? x.y_max : x.y_min;
    }
    if (!any) continue;
    out.row(first);
    out.row(second);
  }
  out.close();
}

}  // namespace feeddrive::output
