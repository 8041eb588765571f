#pragma once
// Quantiles of a stream of doubles in bounded memory: a histogram over the bit pattern of the
// values.
//
// Method. A finite double is mapped to a 64-bit key that orders like the value (sign flipped
// for positives, all bits flipped for negatives: the IEEE-754 total order). The bucket of a
// value is its sign, its 11 exponent bits and the top kMantissaBits = 10 bits of its mantissa,
// i.e. the top 22 bits of the key. Inside one binade [2^e, 2^(e+1)) the buckets are 2^(e-10)
// wide, so a bucket [lo, hi) of normal numbers has hi/lo <= 1 + 2^-10. Buckets are stored in
// blocks of 1024 counters, one block per (sign, exponent) allocated when first used: memory is
// at most 4096 blocks x 8 KiB (32 MiB) whatever the number of values, and in practice a few
// dozen blocks (a run's errors span a few decades).
//
// Result. value_at_rank(k) is the k-th smallest value (0-based). It returns the middle of the
// bucket that holds it, clamped to the exact minimum and maximum seen, so
//   |returned - exact| <= (hi - lo)/2 <= 2^-11 |exact|   (about 0.05 %)
// for normal numbers; subnormal buckets are 2^-1084 wide (absolute bound). Zero (either sign)
// and the extremes are exact. NaN values are counted apart (nan_count) and never ranked.
//
// Same idea as HdrHistogram's log-linear buckets (G. Tene) and DDSketch's relative-error
// guarantee (Masson, Rim, Lee, "DDSketch", VLDB 2019), here with the buckets read directly off
// the IEEE-754 representation.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>

namespace feeddrive::stats {

class StreamingQuantile {
 public:
  static constexpr int kMantissaBits = 10;
  static constexpr int kBlockBits = kMantissaBits;        // buckets per block: 2^10
  static constexpr int kBlocks = 1 << 12;                 // sign + 11 exponent bits
  static constexpr int kShift = 64 - 12 - kMantissaBits;  // key bits dropped inside a bucket

  StreamingQuantile() = default;
  StreamingQuantile(StreamingQuantile&&) = default;
  StreamingQuantile& operator=(StreamingQuantile&&) = default;

  void add(double v) {
    if (std::isnan(v)) {
      ++nan_;
      return;
    }
    const std::uint64_t key = key_of(v);
    const std::size_t block = static_cast<std::size_t>(key >> 52);
    const std::size_t bucket = static_cast<std::size_t>((key >> kShift) & ((1u << kBlockBits) - 1));
    auto& b = blocks_[block];
    if (!b) b = std::make_unique<Block>();  // value-initialised: zeros
    ++(*b)[bucket];
    if (n_ == 0 || v < min_) min_ = v;
    if (n_ == 0 || v > max_) max_ = v;
    ++n_;
  }

  std::uint64_t count() const { return n_; }  ///< values ranked (NaN excluded)
  std::uint64_t nan_count() const { return nan_; }
  double min() const { return n_ ? min_ : std::numeric_limits<double>::quiet_NaN(); }
  double max() const { return n_ ? max_ : std::numeric_limits<double>::quiet_NaN(); }

  /// The k-th smallest value (0-based, k < count()), within the bound above; NaN if empty.
  double value_at_rank(std::uint64_t k) const {
    if (n_ == 0) return std::numeric_limits<double>::quiet_NaN();
    if (k == 0) return min_;
    if (k >= n_ - 1) return max_;
    std::uint64_t seen = 0;
    for (std::size_t blk = 0; blk < blocks_.size(); ++blk) {
      if (!blocks_[blk]) continue;
      const Block& b = *blocks_[blk];
      for (std::size_t i = 0; i < b.size(); ++i) {
        seen += b[i];
        if (seen > k) {
          const std::uint64_t lo_key =
              (static_cast<std::uint64_t>(blk) << 52) | (static_cast<std::uint64_t>(i) << kShift);
          const std::uint64_t hi_key = lo_key | ((std::uint64_t{1} << kShift) - 1);
          const double a = value_of(lo_key), c = value_of(hi_key);
          double mid = a + (c - a) / 2;
          if (!std::isfinite(mid)) mid = std::isnan(a) ? c : a;  // the buckets of +-inf
          if (a == 0.0 || c == 0.0) mid = a == 0.0 ? a : c;      // the bucket holding zero is exact
          return std::clamp(mid, min_, max_);
        }
      }
    }
    return max_;
  }

  /// The p-quantile by the nearest-rank rule k = floor(p (n - 1)).
  double quantile(double p) const {
    if (n_ == 0) return std::numeric_limits<double>::quiet_NaN();
    const double r = std::clamp(p, 0.0, 1.0) * static_cast<double>(n_ - 1);
    return value_at_rank(static_cast<std::uint64_t>(r));
  }

  /// Monotone map of a double to a key (IEEE-754 total order); inverse value_of.
  static std::uint64_t key_of(double v) {
    std::uint64_t b;
    std::memcpy(&b, &v, sizeof b);
    return (b >> 63) ? ~b : (b | (std::uint64_t{1} << 63));
  }
  static double value_of(std::uint64_t key) {
    const std::uint64_t b = (key >> 63) ? (key & ~(std::uint64_t{1} << 63)) : ~key;
    double v;
    std::memcpy(&v, &b, sizeof v);
    return v;
  }

 private:
  using Block = std::array<std::uint64_t, std::size_t{1} << kBlockBits>;
  std::array<std::unique_ptr<Block>, kBlocks> blocks_{};
  std::uint64_t n_{0}, nan_{0};
  double min_{0.0}, max_{0.0};
};

}  // namespace feeddrive::stats
