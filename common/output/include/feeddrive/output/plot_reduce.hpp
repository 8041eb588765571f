#pragma once
// Curves reduced to what a plot can show: for each of B buckets of the time axis (one per pixel
// column of the plot) and each curve, the smallest and the largest sample with their times.
// Drawn as a line through (t_first, y_first), (t_second, y_second) of every bucket (the two
// extremes in time order), the reduced curve covers exactly the band the full curve covers in
// each pixel column: every peak stays visible, a chattering signal stays a filled band, and the
// plot costs O(B) whatever the number of samples (the "min/max decimation" of oscilloscopes and
// of M4, Jugel et al., "M4: A Visualization-Oriented Time Series Data Aggregation", VLDB 2014).
//
// Streaming: add() takes the samples in any order, memory is B x curves x 5 numbers.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace feeddrive::output {

class MinMaxReducer {
 public:
  struct Extremes {
    double t_min{0.0}, y_min{0.0};
    double t_max{0.0}, y_max{0.0};
    std::uint64_t n{0};  ///< finite samples in the bucket
  };

  /// Buckets of equal width over [t0, t1] (t1 > t0; a sample outside goes to the end bucket).
  MinMaxReducer(double t0, double t1, std::size_t buckets, std::size_t curves);

  /// One sample time and the value of each curve (values[curves]); NaN and inf values are
  /// skipped (they have no place on the axis).
  void add(double t, const double* values);

  std::size_t buckets() const { return buckets_; }
  std::size_t curves() const { return curves_; }
  std::size_t bucket_of(double t) const;
  const Extremes& at(std::size_t bucket, std::size_t curve) const { return e_[bucket * curves_ + curve]; }
  /// Whether curve `curve` has a finite sample anywhere (a plot of none has no axis range).
  bool has_samples(std::size_t curve) const;

  /// The plot data: header "t_<name>,<name>" for each curve, then two rows per non-empty bucket,
  /// each curve's two extremes in time order ("nan,nan" for a curve without samples there).
  /// Curve c is at columns 2c+1 (time) and 2c+2 (value) for gnuplot's `using`.
  void write_csv(const std::filesystem::path& path, const std::vector<std::string>& names) const;

 private:
  double t0_, scale_;
  std::size_t buckets_, curves_;
  std::vector<Extremes> e_;
};

}  // namespace feeddrive::output
