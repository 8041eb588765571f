#include "feeddrive/fit/data.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "feeddrive/monitor/log_reader.hpp"

namespace feeddrive::fit {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream ss(line);
  while (std::getline(ss, cell, ',')) out.push_back(trim(cell));
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

std::string short_value(const std::string& s) { return s.size() > 40 ? s.substr(0, 40) + "..." : s; }

}  // namespace

double MeasuredData::median_period() const {
  if (t.size() < 2) return 0.0;
  std::vector<double> d(t.size() - 1);
  for (std::size_t k = 0; k + 1 < t.size(); ++k) d[k] = t[k + 1] - t[k];
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

void validate(const MeasuredData& d) {
  const std::size_t n = d.t.size();
  if (d.x.size() != n || d.input.size() != n || (!d.xd.empty() && d.xd.size() != n) ||
      (!d.v.empty() && d.v.size() != n))
    throw DataError(d.source + ": columns of different lengths");
  if (n < kMinSamples)
    throw DataError(d.source + ": " + std::to_string(n) + " samples: too few (at least " +
                    std::to_string(kMinSamples) + ")");
  for (std::size_t k = 0; k < n; ++k) {
    const auto bad = [&](const char* col, double v) {
      throw DataError(d.source + ": sample " + std::to_string(k) + ", column " + col + ": " + std::to_string(v) +
                      " is not a finite number");
    };
    if (!std::isfinite(d.t[k])) bad("t", d.t[k]);
    if (!std::isfinite(d.x[k])) bad("x", d.x[k]);
    if (!std::isfinite(d.input[k])) bad(d.input_kind == InputKind::kCommand ? "u" : "force_N", d.input[k]);
    if (!d.xd.empty() && !std::isfinite(d.xd[k])) bad("xd", d.xd[k]);
    if (!d.v.empty() && !std::isfinite(d.v[k])) bad("v", d.v[k]);
    if (k > 0 && !(d.t[k] > d.t[k - 1]))
      throw DataError(d.source + ": sample " + std::to_string(k) + ", column t: " + std::to_string(d.t[k]) +
                      " does not increase (previous " + std::to_string(d.t[k - 1]) + ")");
  }
}

MeasuredData parse_csv(const std::string& text, const std::string& origin, const CsvOptions& opt) {
  MeasuredData d;
  d.source = origin;
  std::istringstream in(text);
  std::string line;
  long line_no = 0;
  std::vector<std::string> header;
  while (std::getline(in, line)) {
    ++line_no;
    if (line_no == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // UTF-8 byte-order mark
    if (!trim(line).empty()) {
      header = split(line);
      break;
    }
  }
  if (header.empty()) throw DataError(origin + ": empty file (expected a CSV header with t, x and u or force_N)");
  std::map<std::string, std::size_t> col;
  for (std::size_t c = 0; c < header.size(); ++c) {
    if (header[c].empty()) throw DataError(origin + ": line " + std::to_string(line_no) + ": empty column name " +
                                           std::to_string(c + 1));
    if (!col.emplace(header[c], c).second)
      throw DataError(origin + ": line " + std::to_string(line_no) + ": column '" + header[c] + "' appears twice");
  }
  const std::string hint = (header.size() == 1 && (line.find(';') != std::string::npos || line.find('\t') != std::string::npos))
                               ? "; columns must be separated by commas"
                               : "";
  const auto require = [&](const std::string& name) {
    const auto it = col.find(name);
    if (it == col.end())
      throw DataError(origin + ": missing column '" + name + "' (header: " + short_value(line) + hint + ")");
    return it->second;
  };
  const std::size_t ct = require(opt.time_column);
  const std::size_t cx = require(opt.position_column);
  std::size_t cu;
  if (col.count(opt.command_column)) {
    cu = col[opt.command_column];
    d.input_kind = InputKind::kCommand;
  } else if (col.count(opt.force_column)) {
    cu = col[opt.force_column];
    d.input_kind = InputKind::kForce;
  } else {
    throw DataError(origin + ": missing column '" + opt.command_column + "' or '" + opt.force_column +
                    "' (the input; header: " + short_value(line) + hint + ")");
  }
  const long cxd = col.count(opt.reference_column) ? static_cast<long>(col[opt.reference_column]) : -1;
  const long cv = col.count("v") ? static_cast<long>(col["v"]) : -1;

  std::string previous_t;
  while (std::getline(in, line)) {
    ++line_no;
    if (trim(line).empty()) continue;
    const std::vector<std::string> cells = split(line);
    if (cells.size() != header.size())
      throw DataError(origin + ": line " + std::to_string(line_no) + ": " + std::to_string(cells.size()) +
                      " columns, the header has " + std::to_string(header.size()) + " (truncated row?)");
    const auto number = [&](std::size_t c) {
      const std::string& s = cells[c];
      const char* b = s.c_str();
      char* end = nullptr;
      errno = 0;
      const double v = std::strtod(b, &end);
      if (s.empty() || end != b + s.size() || errno == ERANGE || !std::isfinite(v))
        throw DataError(origin + ": line " + std::to_string(line_no) + ", column " + header[c] + ": '" +
                        short_value(s) + "' is not a finite number");
      return v;
    };
    const double t = number(ct);
    if (!d.t.empty() && !(t > d.t.back()))
      throw DataError(origin + ": line " + std::to_string(line_no) + ", column " + header[ct] + ": " + cells[ct] +
                      (t == d.t.back() ? " repeats the previous time" : " is before the previous time " + previous_t) +
                      " (times must increase)");
    previous_t = cells[ct];
    d.t.push_back(t);
    d.x.push_back(number(cx));
    d.input.push_back(number(cu));
    if (cxd >= 0) d.xd.push_back(number(static_cast<std::size_t>(cxd)));
    if (cv >= 0) d.v.push_back(number(static_cast<std::size_t>(cv)));
  }
  validate(d);
  return d;
}

MeasuredData load_csv(const std::string& path, const CsvOptions& opt) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw DataError(path + ": is a folder, not a data file");
  std::ifstream f(path, std::ios::binary);
  if (!f) throw DataError(path + ": cannot open the data file");
  std::ostringstream ss;
  ss << f.rdbuf();
  if (f.bad()) throw DataError(path + ": read error");
  return parse_csv(ss.str(), path, opt);
}

MeasuredData load_lcm_log(const std::string& path, const std::string& prefix) {
  monitor::LogConversion c;
  std::vector<sim::Record> rows;
  try {
    c = monitor::read_log(path, prefix, [&](const sim::Record& r) { rows.push_back(r); });
  } catch (const std::exception& e) {
    throw DataError(e.what());
  }
  if (rows.empty())
    throw DataError(path + ": no complete step on channels " + prefix + "_STATE/_REF/_CMD (" +
                    std::to_string(c.events) + " events read; wrong --prefix?)");
  MeasuredData d;
  d.source = path;
  d.input_kind = InputKind::kCommand;
  for (const auto& r : rows) {
    d.t.push_back(r.t);
    d.x.push_back(r.x_measured);
    d.input.push_back(r.u);
    d.xd.push_back(r.xd);
    d.v.push_back(r.v_measured);
  }
  validate(d);
  return d;
}

MeasuredData load_data(const std::string& path, const std::string& prefix, const CsvOptions& opt) {
  const auto dot = path.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  if (ext == ".lcm" || ext == ".lcmlog" || ext == ".log") return load_lcm_log(path, prefix);
  return load_csv(path, opt);
}

}  // namespace feeddrive::fit
