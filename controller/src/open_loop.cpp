#include "feeddrive/controller/open_loop.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "check.hpp"

namespace feeddrive::controller {

std::string to_string(OpenLoopKind k) {
  switch (k) {
    case OpenLoopKind::kStep: return "step";
    case OpenLoopKind::kSine: return "sine";
    case OpenLoopKind::kRamp: return "ramp";
    case OpenLoopKind::kCsv: return "csv";
  }
  return "?";
}

OpenLoopKind open_loop_kind_from_string(const std::string& s) {
  if (s == "step") return OpenLoopKind::kStep;
  if (s == "sine") return OpenLoopKind::kSine;
  if (s == "ramp") return OpenLoopKind::kRamp;
  if (s == "csv") return OpenLoopKind::kCsv;
  throw std::invalid_argument("expected one of step, sine, ramp, csv");
}

void OpenLoopParams::validate(const std::string& prefix) const {
  using namespace detail;
  require_finite(prefix + ".amplitude", amplitude);
  require_non_negative(prefix + ".frequency", frequency);
  require_finite(prefix + ".phase", phase);
  require_finite(prefix + ".offset", offset);
  require_finite(prefix + ".rate", rate);
  require_non_negative(prefix + ".start_time", start_time);
  require_positive(prefix + ".thrust_gain", thrust_gain);
  require_range(prefix, u_min, u_max);
  if (kind == OpenLoopKind::kCsv && file.empty())
    throw std::invalid_argument(prefix + ".file = '': kind = csv needs a file");
}

namespace {

[[noreturn]] void csv_fail(const std::string& file, int line, const std::string& why) {
  throw std::invalid_argument(file + ":" + std::to_string(line) + ": " + why);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream is(line);
  while (std::getline(is, cell, ',')) {
    const auto b = cell.find_first_not_of(" \t\r");
    const auto e = cell.find_last_not_of(" \t\r");
    out.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
  }
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

}  // namespace

OpenLoopSource::OpenLoopSource(const OpenLoopParams& p) : p_(p) {
  p_.validate("controller");
  if (p_.kind != OpenLoopKind::kCsv) return;
  std::ifstream in(p_.file);
  if (!in) throw std::invalid_argument("controller.file = '" + p_.file + "': cannot open the file");
  std::string line;
  int n = 0;
  int col_t = -1, col_v = -1;
  bool is_force = true;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty() || line == "\r" || line[0] == '#') continue;
    const auto cells = split(line);
    if (col_t < 0) {  // header
      for (int i = 0; i < static_cast<int>(cells.size()); ++i) {
        if (cells[i] == "t") col_t = i;
        if (cells[i] == "force_N") { col_v = i; is_force = true; }
        if (cells[i] == "u" && col_v < 0) { col_v = i; is_force = false; }
      }
      if (col_t < 0) csv_fail(p_.file, n, "header '" + line + "' has no column 't'");
      if (col_v < 0) csv_fail(p_.file, n, "header '" + line + "' has no column 'force_N' or 'u'");
      continue;
    }
    const int need = std::max(col_t, col_v);
    if (static_cast<int>(cells.size()) <= need)
      csv_fail(p_.file, n, "row '" + line + "' has " + std::to_string(cells.size()) +
                               " columns, the header names " + std::to_string(need + 1));
    double vals[2];
    const int cols[2] = {col_t, col_v};
    for (int j = 0; j < 2; ++j) {
      const std::string& c = cells[cols[j]];
      char* end = nullptr;
      vals[j] = std::strtod(c.c_str(), &end);
      if (c.empty() || end != c.c_str() + c.size() || !std::isfinite(vals[j]))
        csv_fail(p_.file, n, (j == 0 ? "t" : (is_force ? "force_N" : "u")) + std::string(" = '") + c +
                                 "': not a finite number");
    }
    if (!csv_t_.empty() && !(vals[0] > csv_t_.back()))
      csv_fail(p_.file, n, "t = " + cells[col_t] + ": times must increase strictly");
    csv_t_.push_back(vals[0]);
    csv_u_.push_back(is_force ? vals[1] / p_.thrust_gain : vals[1]);
  }
  if (csv_t_.empty()) csv_fail(p_.file, n, "no data rows");
}

double OpenLoopSource::force(double t) const {
  if (p_.kind == OpenLoopKind::kCsv) {
    // Zero-order hold; before the first row the force is 0.
    const auto it = std::upper_bound(csv_t_.begin(), csv_t_.end(), t);
    if (it == csv_t_.begin()) return 0.0;
    return csv_u_[static_cast<std::size_t>(it - csv_t_.begin()) - 1] * p_.thrust_gain;
  }
  if (t < p_.start_time) return p_.offset;
  const double tau = t - p_.start_time;
  switch (p_.kind) {
    case OpenLoopKind::kStep: return p_.offset + p_.amplitude;
    case OpenLoopKind::kSine:
      return p_.offset + p_.amplitude * std::sin(2.0 * M_PI * p_.frequency * tau + p_.phase);
    case OpenLoopKind::kRamp: {
      double f = p_.rate * tau;
      if (p_.amplitude > 0.0) f = std::clamp(f, -p_.amplitude, p_.amplitude);
      return p_.offset + f;
    }
    case OpenLoopKind::kCsv: break;
  }
  return 0.0;
}

Command OpenLoopSource::update(const trajectory::Sample& /*ref*/, const plant::Measurement& meas,
                               const Truth* /*truth*/) {
  Command cmd;
  cmd.u_unsaturated = force(meas.t) / p_.thrust_gain;
  cmd.u = saturate(cmd.u_unsaturated, p_.u_min, p_.u_max);
  return cmd;
}

}  // namespace feeddrive::controller
