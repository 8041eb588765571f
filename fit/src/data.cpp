#include "feeddrive/fit/data.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "feeddrive/csv/reader.hpp"
#include "feeddrive/record/log_reader.hpp"

namespace feeddrive::fit {
double MeasuredData::median_period() const {
  if (t.size() < 2) return 0.0;
  std::vector<double> d(t.size() - 1);
  for (std::size_t k = 0; k + 1 < t.size(); ++k) d[k] = t[k + 1] - t[k];
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

double smallest_position_step(const MeasuredData& d) {
  double q = std::numeric_limits<double>::infinity();
  for (std::size_t k = 1; k < d.size(); ++k)
    if (d.x[k] != d.x[k - 1]) q = std::min(q, std::abs(d.x[k] - d.x[k - 1]));
  return std::isfinite(q) ? q : 0.0;
}

void validate(const MeasuredData& d) {
  const std::size_t n = d.t.size();
  if (d.x.size() != n || d.input.size() != n || (!d.xd.empty() && d.xd.size() != n) ||
      (!d.v.empty() && d.v.size() != n))
    throw DataError(d.source + ": columns of different lengths");
  if (n < kMinSamples)
    throw DataError(d.source + ": " + std::to_string(n) + " samples: too few (at least " + std::to_string(kMinSamples) +
                    ")");
  for (std::size_t k = 0; k < n; ++k) {
    const auto bad = [&](const char* col, double v) {
      throw DataError(d.source + ": sample " + std::to_string(k) + ", column " + col + ": " + std::to_string(v) +
                      " is not a finite number");
    };
    if (!std::isfinite(d.t[k])) bad(d.time_name.c_str(), d.t[k]);
    if (!std::isfinite(d.x[k])) bad(d.position_name.c_str(), d.x[k]);
    if (!std::isfinite(d.input[k])) bad(d.input_name.c_str(), d.input[k]);
    if (!d.xd.empty() && !std::isfinite(d.xd[k])) bad("xd", d.xd[k]);
    if (!d.v.empty() && !std::isfinite(d.v[k])) bad("v", d.v[k]);
    if (k > 0 && !(d.t[k] > d.t[k - 1]))
      throw DataError(d.source + ": sample " + std::to_string(k) + ", column t: " + std::to_string(d.t[k]) +
                      " does not increase (previous " + std::to_string(d.t[k - 1]) + ")");
  }
}

std::string MeasuredData::where(std::size_t k) const {
  if (k < lines.size()) return source + ":" + std::to_string(lines[k]);
  return source + ", sample " + std::to_string(k);
}

Units parse_units(const std::string& spec) {
  Units u;
  u.text = spec;
  std::size_t start = 0;
  while (start <= spec.size()) {
    const auto comma = spec.find(',', start);
    const std::string item = spec.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    start = comma == std::string::npos ? spec.size() + 1 : comma + 1;
    if (item.empty()) continue;
    const auto eq = item.find('=');
    const std::string role = item.substr(0, eq), unit = eq == std::string::npos ? "" : item.substr(eq + 1);
    const auto bad = [&](const std::string& why) {
      throw DataError(
          "--units '" + csv::shown(item) + "': " + why +
          " (ROLE=UNIT with t: s, ms, us; x, xd: m, mm, um, nm; force: N, kN, mN; u: V, mV; any: counts:SCALE)");
    };
    double* target = role == "t"       ? &u.t
                     : role == "x"     ? &u.x
                     : role == "xd"    ? &u.xd
                     : role == "force" ? &u.force
                     : role == "u"     ? &u.u
                                       : nullptr;
    // a logger's file often has a velocity column: the fit uses none (it takes the motion from
    // the position), so it needs no unit; either way the roles it does use are named
    const std::string roles = "the roles are t (time), x (position), xd (reference), force (thrust), u (command)";
    if (!target && (role == "v" || role == "velocity" || role == "speed"))
      bad("the fit uses no velocity column (it takes the motion from the position): leave it out of --units; " + roles);
    if (!target) bad("unknown role '" + csv::shown(role) + "': " + roles);
    if (unit.empty()) bad("no unit");
    static const std::map<std::string, std::map<std::string, double>> table{
        {"t", {{"s", 1.0}, {"ms", 1e-3}, {"us", 1e-6}}},
        {"x", {{"m", 1.0}, {"mm", 1e-3}, {"um", 1e-6}, {"nm", 1e-9}}},
        {"xd", {{"m", 1.0}, {"mm", 1e-3}, {"um", 1e-6}, {"nm", 1e-9}}},
        {"force", {{"N", 1.0}, {"kN", 1e3}, {"mN", 1e-3}}},
        {"u", {{"V", 1.0}, {"mV", 1e-3}}}};
    if (unit.rfind("counts:", 0) == 0) {
      const std::string sc = unit.substr(7);
      char* end = nullptr;
      const double v = std::strtod(sc.c_str(), &end);
      if (sc.empty() || *end != '\0' || !std::isfinite(v) || !(v > 0))
        bad("the scale of counts must be a positive number");
      *target = v;
      continue;
    }
    const auto& units = table.at(role);
    const auto it = units.find(unit);
    if (it == units.end()) bad("unknown unit '" + csv::shown(unit) + "' for " + role);
    *target = it->second;
  }
  return u;
}

namespace {

// The columns of the roles, for the one CSV reader (feeddrive/csv/reader.hpp).
csv::Options csv_options(const CsvOptions& opt) {
  csv::Options o;
  o.separator = opt.separator;
  o.decimal_comma = opt.decimal_comma;
  o.columns_by_index = true;
  o.separator_option = "--separator";
  o.decimal_comma_option = "--decimal-comma";
  o.columns = {{{opt.time_column}},
               {{opt.position_column}},
               {{opt.command_column, opt.force_column}},
               {{opt.reference_column}, false},
               {{"v"}, false}};
  o.increasing = 0;
  return o;
}

MeasuredData from_table(csv::Table t, const CsvOptions& opt) {
  MeasuredData d;
  d.source = t.source;
  d.t = std::move(t.values[0]);
  d.x = std::move(t.values[1]);
  d.input = std::move(t.values[2]);
  // the command column is the first alternative, the force column the second
  d.input_kind = t.alternative[2] == 0 ? InputKind::kCommand : InputKind::kForce;
  d.xd = std::move(t.values[3]);
  d.v = std::move(t.values[4]);
  d.lines = std::move(t.lines);
  d.time_name = t.used[0];
  d.position_name = t.used[1];
  d.input_name = t.used[2];
  const Units& u = opt.units;
  d.time_factor = u.t;
  d.position_factor = u.x;
  d.input_factor = d.input_kind == InputKind::kForce ? u.force : u.u;
  const auto scale = [](std::vector<double>& v, double f) {
    if (f != 1.0)
      for (double& y : v) y *= f;
  };
  scale(d.t, d.time_factor);
  scale(d.x, d.position_factor);
  scale(d.input, d.input_factor);
  scale(d.xd, u.xd);
  scale(d.v, d.position_factor / d.time_factor);
  if (!u.text.empty()) d.notes.push_back("units " + u.text + " converted to SI on loading");
  validate(d);
  return d;
}

}  // namespace

MeasuredData load_csv(const std::string& path, const CsvOptions& opt) {
  try {
    return from_table(csv::read_file(path, csv_options(opt)), opt);
  } catch (const csv::CsvError& e) {
    throw DataError(e.what());
  }
}

MeasuredData load_lcm_log(const std::string& path, const std::string& prefix, const interrupt::StopToken& stop) {
  record::LogConversion c;
  std::vector<sim::Record> rows;
  std::string notes_tail;
  try {
    c = record::read_log(
        path, prefix, [&](const sim::Record& r) { rows.push_back(r); }, /*need_reference=*/false, stop);
  } catch (const std::exception& e) {
    throw DataError(e.what());
  }
  if (rows.empty())
    throw DataError(path + ": no complete step on channels " + prefix + "_STATE/_REF/_CMD (" +
                    std::to_string(c.events) + " events read; " +
                    (c.cut_bytes > 0 ? record::describe_cut(c) : std::string("wrong --prefix?")) + ")");
  // A gap that runs to the end (the log stops early: the logger was stopped, or its last event
  // was cut short) only shortens the record; a gap inside it cannot be replayed.
  auto gaps = c.recorder.gaps();
  if (!gaps.empty() && gaps.back().last == c.recorder.steps() - 1) {
    notes_tail = "the log stops after step " + std::to_string(gaps.back().first - 1) + " of " +
                 std::to_string(c.recorder.steps()) + ": the record ends there";
    gaps.pop_back();
  }
  if (!gaps.empty())
    throw DataError(path + ": " + record::describe_gaps(gaps) + " of " + std::to_string(c.recorder.steps()) +
                    "; the fit needs every state (position and applied input); " +
                    "feeddrive-log2csv writes the complete steps");
  MeasuredData d;
  d.source = path;
  d.input_kind = InputKind::kCommand;
  bool all_xd = true;
  for (const auto& r : rows) {
    d.t.push_back(r.t);
    d.x.push_back(r.x_measured);
    d.input.push_back(r.u);
    d.xd.push_back(r.xd);
    d.v.push_back(r.v_measured);
    all_xd = all_xd && std::isfinite(r.xd);
  }
  if (!all_xd) {
    d.xd.clear();
    d.notes.push_back("some reference messages are missing from the log: the record has no xd column");
  }
  if (const auto n = c.recorder.commandless_rows(); n > 0)
    d.notes.push_back(
        std::to_string(n) + " of " + std::to_string(rows.size()) +
        " steps have no command in the log: their input is the one the plant applied (from its next state)");
  if (c.non_finite > 0)
    d.notes.push_back(std::to_string(c.non_finite) + " messages with a non-finite value were dropped");
  if (c.cut_bytes > 0) d.notes.push_back(record::describe_cut(c));
  if (!notes_tail.empty()) d.notes.push_back(notes_tail);
  validate(d);
  return d;
}

MeasuredData load_data(const std::string& path, const std::string& prefix, const CsvOptions& opt,
                       const interrupt::StopToken& stop) {
  const auto dot = path.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  MeasuredData d =
      (ext == ".lcm" || ext == ".lcmlog" || ext == ".log") ? load_lcm_log(path, prefix, stop) : load_csv(path, opt);
  shift_time_origin(d);
  return d;
}

void shift_time_origin(MeasuredData& d) {
  if (d.t.empty() || d.t.front() == 0.0) return;
  const double t0 = d.t.front();
  for (double& t : d.t) t -= t0;  // exact for t within a factor 2 of t0 (Sterbenz), close to it otherwise
  d.time_offset += t0;
  char buf[96];
  std::snprintf(buf, sizeof buf, "time stamps shifted by %.17g s to start at 0", -t0);
  d.notes.push_back(buf);
  validate(d);  // a shift can merge time stamps that differ in their last bits
}

}  // namespace feeddrive::fit
