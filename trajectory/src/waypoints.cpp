// Waypoint references: a natural cubic spline through (t_i, x_i), and the CSV reader.
//
// Spline: e.g. Burden & Faires, "Numerical Analysis", 9th ed., Sec. 3.5 "Cubic Spline
// Interpolation"; de Boor, "A Practical Guide to Splines", Ch. IV. Knots t_0 < ... < t_n, h_i =
// t_{i+1} - t_i, unknown second derivatives M_i = x''(t_i) with the natural end conditions M_0 =
// M_n = 0 and, for i = 1..n-1, the tridiagonal (strictly diagonally dominant) system
//   h_{i-1} M_{i-1} + 2 (h_{i-1} + h_i) M_i + h_i M_{i+1}
//       = 6 ((x_{i+1} - x_i)/h_i - (x_i - x_{i-1})/h_{i-1}),
// solved by the Thomas algorithm (no pivoting needed). On [t_i, t_{i+1}), with u = t - t_i:
//   x = x_i + b_i u + (M_i/2) u^2 + d_i u^3,   b_i = (x_{i+1} - x_i)/h_i - h_i (2 M_i + M_{i+1})/6,
//   d_i = (M_{i+1} - M_i)/(6 h_i);  v = b_i + M_i u + 3 d_i u^2,  a = M_i + 6 d_i u,  j = 6 d_i.
// Written in u from the left knot, x(t_i) = x_i exactly. With two points M = 0: a straight line.
// Outside [t_0, t_n] the sample is the end value with zero derivatives.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "check.hpp"
#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::trajectory {
namespace {

constexpr std::size_t kMinPoints = 2;             // a spline needs at least one interval
constexpr const char* kUtf8Bom = "\xEF\xBB\xBF";  // skipped at the start of a CSV file

class Waypoints final : public Trajectory {
 public:
  explicit Waypoints(std::vector<Waypoint> points) : p_(std::move(points)) {
    const std::size_t n = p_.size() - 1;  // number of intervals
    std::vector<double> h(n);
    for (std::size_t i = 0; i < n; ++i) h[i] = p_[i + 1].t - p_[i].t;
    m_.assign(n + 1, 0.0);  // natural ends: M_0 = M_n = 0
    if (n >= 2) {
      // Thomas algorithm on the interior unknowns M_1..M_{n-1}.
      std::vector<double> diag(n + 1, 0.0);
      std::vector<double> rhs(n + 1, 0.0);
      for (std::size_t i = 1; i < n; ++i) {
        diag[i] = 2.0 * (h[i - 1] + h[i]);
        rhs[i] = 6.0 * ((p_[i + 1].x - p_[i].x) / h[i] - (p_[i].x - p_[i - 1].x) / h[i - 1]);
      }
      for (std::size_t i = 2; i < n; ++i) {  // forward elimination (sub-diagonal h_{i-1})
        const double w = h[i - 1] / diag[i - 1];
        diag[i] -= w * h[i - 1];
        rhs[i] -= w * rhs[i - 1];
      }
      for (std::size_t i = n - 1; i >= 1; --i) {  // back substitution (super-diagonal h_i)
        m_[i] = (rhs[i] - h[i] * m_[i + 1]) / diag[i];
      }
    }
    b_.resize(n);
    d_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      b_[i] = (p_[i + 1].x - p_[i].x) / h[i] - h[i] * (2.0 * m_[i] + m_[i + 1]) / 6.0;
      d_[i] = (m_[i + 1] - m_[i]) / (6.0 * h[i]);
    }
  }

  Sample sample(double t) const override {
    if (std::isnan(t)) return detail::nan_sample();
    if (t < p_.front().t) return {p_.front().x, 0.0, 0.0, 0.0};
    if (t >= p_.back().t) return {p_.back().x, 0.0, 0.0, 0.0};
    // Interval i with t_i <= t < t_{i+1}.
    const auto it = std::upper_bound(p_.begin(), p_.end(), t,
                                     [](double value, const Waypoint& w) { return value < w.t; });
    const std::size_t i = static_cast<std::size_t>(std::distance(p_.begin(), it)) - 1;
    const double u = t - p_[i].t;
    const double c = 0.5 * m_[i];
    return {p_[i].x + u * (b_[i] + u * (c + u * d_[i])), b_[i] + u * (m_[i] + 3.0 * d_[i] * u),
            m_[i] + 6.0 * d_[i] * u, 6.0 * d_[i]};
  }
  double end_time() const override { return p_.back().t; }

 private:
  std::vector<Waypoint> p_;
  std::vector<double> m_;  // M_i = x''(t_i) [m/s^2]
  std::vector<double> b_;  // x'(t_i) on interval i [m/s]
  std::vector<double> d_;  // x'''/6 on interval i [m/s^3]
};

// ------------------------------------------------------------------------------------------
// CSV reading.

// Strips spaces, tabs and a trailing '\r' (files written on Windows).
std::string trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  const auto last = s.find_last_not_of(" \t\r");
  return s.substr(first, last - first + 1);
}

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    fields.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return fields;
}

// Header names may be double-quoted ("t").
std::string unquote(const std::string& s) {
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') return s.substr(1, s.size() - 2);
  return s;
}

enum class Parse { kOk, kNotANumber, kOutOfRange };

// Locale-independent parse of a whole field; accepts a leading '+', "nan" and "inf".
Parse parse_double(const std::string& text, double* out) {
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (first != last && *first == '+') ++first;
  if (first == last) return Parse::kNotANumber;
  const auto res = std::from_chars(first, last, *out);
  if (res.ptr != last) return Parse::kNotANumber;
  if (res.ec == std::errc::result_out_of_range) return Parse::kOutOfRange;  // 1e999, 1e-999
  return res.ec == std::errc() ? Parse::kOk : Parse::kNotANumber;
}

[[noreturn]] void csv_fail(const std::string& path, std::size_t line, const std::string& what) {
  throw std::invalid_argument(path + ":" + std::to_string(line) + ": " + what);
}

}  // namespace

std::unique_ptr<Trajectory> make_waypoints(const std::vector<Waypoint>& points) {
  if (points.size() < kMinPoints)
    throw std::invalid_argument("waypoints: need at least 2 points, got " +
                                std::to_string(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::string key = "waypoints[" + std::to_string(i) + "]";
    detail::require_finite(key + ".t", points[i].t);
    detail::require_finite(key + ".x", points[i].x);
    if (i > 0 && !(points[i].t > points[i - 1].t))
      detail::fail(
          key + ".t", points[i].t,
          "must be greater than the previous t = " + detail::format_number(points[i - 1].t));
  }
  return std::make_unique<Waypoints>(points);
}

std::vector<Waypoint> read_waypoints_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot open file for reading");

  std::vector<Waypoint> points;
  std::size_t t_col = 0;
  std::size_t x_col = 0;
  bool have_header = false;
  std::string prev_t_text;  // the previous t as written in the file
  std::size_t prev_t_line = 0;
  std::string raw;
  std::size_t line_no = 0;
  while (std::getline(in, raw)) {
    ++line_no;
    if (line_no == 1 && raw.rfind(kUtf8Bom, 0) == 0) raw.erase(0, 3);
    const std::string line = trim(raw);
    if (line.empty() || line.front() == '#') continue;
    const std::vector<std::string> fields = split_fields(line);

    if (!have_header) {
      std::optional<std::size_t> t_index;
      std::optional<std::size_t> x_index;
      for (std::size_t c = 0; c < fields.size(); ++c) {
        const std::string name = unquote(fields[c]);
        std::optional<std::size_t>* slot = name == "t"   ? &t_index
                                           : name == "x" ? &x_index
                                                         : nullptr;
        if (slot == nullptr) continue;  // another column: ignored
        if (slot->has_value())
          csv_fail(path, line_no, "duplicate column '" + name + "' in the header");
        *slot = c;
      }
      if (!t_index) csv_fail(path, line_no, "missing column 't' in the header '" + line + "'");
      if (!x_index) csv_fail(path, line_no, "missing column 'x' in the header '" + line + "'");
      t_col = *t_index;
      x_col = *x_index;
      have_header = true;
      continue;
    }

    // The value of column `name` (index `col`) of this row, or a one-line error.
    const auto field = [&](const char* name, std::size_t col) {
      const std::string where = std::string("column '") + name + "': ";
      if (col >= fields.size() || fields[col].empty())
        csv_fail(path, line_no, where + "missing value");
      double value = 0.0;
      switch (parse_double(fields[col], &value)) {
        case Parse::kOk:
          break;
        case Parse::kNotANumber:
          csv_fail(path, line_no, where + "not a number: '" + fields[col] + "'");
        case Parse::kOutOfRange:
          csv_fail(path, line_no, where + "out of the range of a double: '" + fields[col] + "'");
      }
      if (!std::isfinite(value))
        csv_fail(path, line_no, where + "not a finite number: '" + fields[col] + "'");
      return value;
    };
    const Waypoint w{field("t", t_col), field("x", x_col)};
    if (!points.empty() && !(w.t > points.back().t))
      csv_fail(path, line_no,
               "column 't': t=" + fields[t_col] + " is not greater than the previous t=" +
                   prev_t_text + " (line " + std::to_string(prev_t_line) + ")");
    prev_t_text = fields[t_col];
    prev_t_line = line_no;
    points.push_back(w);
  }
  if (in.bad()) throw std::invalid_argument(path + ": read error");
  if (!have_header)
    throw std::invalid_argument(path + ": no header line (expected columns 't' and 'x')");
  if (points.size() < kMinPoints)
    throw std::invalid_argument(path + ":" + std::to_string(line_no) +
                                ": need at least 2 data rows, found " +
                                std::to_string(points.size()) + " (end of file)");
  return points;
}

}  // namespace feeddrive::trajectory
