#include "feeddrive/study/report.hpp"

#include "feeddrive/sim/key_tables.hpp"
#include "feeddrive/sim/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "feeddrive/output/csv.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/output/gnuplot.hpp"
#include "feeddrive/sim/summary.hpp"

namespace feeddrive::study {
namespace {

namespace fs = std::filesystem;

// The metric of the report (scaled to its unit), NaN if the case failed or lacks it.
double shown_metric(const Study& s, const Outcome& o) {
  if (!o.ok) return NAN;
  for (const auto& [k, v] : o.metrics)
    if (k == s.report.metric) return v * s.report.scale;
  return NAN;
}

std::string num(double v) {
  if (std::isnan(v)) return "–";
  char buf[64];
  if (v != 0.0 && (std::abs(v) >= 1e5 || std::abs(v) < 1e-3)) {
    std::snprintf(buf, sizeof buf, "%.3g", v);
  } else {
    std::snprintf(buf, sizeof buf, "%.4g", v);
  }
  return buf;
}

// Text from the study in a markdown table cell: no cell breaks, no line breaks.
std::string cell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') {
      out += "\\|";
    } else if (c == '\n' || c == '\r') {
      out += ' ';
    } else {
      out += c;
    }
  }
  return out;
}

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

using Cell = ReportData::Cell;

// A varied key shown by category: some of its values are not numbers, and it has at most
// ReportData::kMaxCategories distinct values.
bool is_categorical(const ReportData& d, std::size_t p) {
  return d.categories[p].text && !d.categories[p].more && !d.categories[p].values.empty();
}

// The pass criterion in words (report.limit and report.require).
std::string criterion_text(const Study& s) {
  std::string t = "A case passes when it ran";
  if (!std::isnan(s.report.limit))
    t += ", its " + s.report.metric + " is at most " + num(s.report.limit) + " " + s.report.unit;
  for (std::size_t i = 0; i < s.report.require.size(); ++i)
    t += (i == 0 ? " and " : ", ") + std::string("`") + s.report.require[i] + "`";
  if (!s.report.require.empty()) t += s.report.require.size() == 1 ? " is true" : " are true";
  return cell(t) + " (`report.limit`, `report.require`).";
}

bool parse_number(const std::string& text, double& out) {
  char* end = nullptr;
  out = std::strtod(text.c_str(), &end);
  return !text.empty() && end == text.c_str() + text.size() && std::isfinite(out);
}

}  // namespace

// A varied key's values in its engineering unit: the unit its params list gives
// (sim::key_unit, which knows the top-level keys too: duration, control_period, ...), scaled to
// mm, um, mm/s, ms or us where the values are that small.
struct AxisUnit {
  std::string unit;
  double factor{1.0};
};
AxisUnit axis_unit(const std::string& key, const std::vector<float>& x, std::size_t stride, std::size_t p) {
  const std::string unit = sim::key_unit(key);
  double top = 0.0;
  for (std::size_t i = p; i < x.size(); i += stride)
    if (std::isfinite(x[i])) top = std::max(top, std::abs(static_cast<double>(x[i])));
  if (unit == "m" && top > 0 && top < 1e-3) return {"um", 1e6};
  if (unit == "m" && top > 0 && top < 1.0) return {"mm", 1e3};
  if (unit == "m/s" && top > 0 && top < 1.0) return {"mm/s", 1e3};
  if (unit == "s" && top > 0 && top < 1e-3) return {"us", 1e6};
  if (unit == "s" && top > 0 && top < 1.0) return {"ms", 1e3};
  return {unit.empty() || unit == "-" ? std::string() : unit, 1.0};
}
std::string axis_label(const std::string& key, const AxisUnit& u) {
  return u.unit.empty() ? key : key + " [" + u.unit + "]";
}

std::string metric_label(const std::string& metric, const std::string& unit) {
  std::string name = metric;
  for (const char* suffix : {"_m", "_s", "_mps", "_mps2", "_N", "_V", "_Hz", "_A", "_W"}) {
    const std::string sfx = suffix;
    if (name.size() > sfx.size() && name.compare(name.size() - sfx.size(), sfx.size(), sfx) == 0) {
      name.resize(name.size() - sfx.size());
      break;
    }
  }
  return unit.empty() ? name : name + " [" + unit + "]";
}

bool log_axis(const Study& s, const std::string& key, const std::vector<double>& values) {
  for (const Family& f : s.families)
    for (const GridAxis& a : f.grid)
      for (const std::string& k : a.keys)
        if (a.log && sim::canonical_key(k) == key) return true;  // key: canonical (varied_keys)
  double lo = INFINITY, hi = 0.0;
  for (double v : values) {
    if (!std::isfinite(v)) continue;
    if (!(v > 0.0)) return false;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  return hi > 0.0 && hi > 100.0 * lo;
}

std::vector<std::string> warning_lines(const ReportData& d) {
  std::vector<std::string> out;
  for (const auto& [w, n] : d.warnings)
    out.push_back(w + " (" + std::to_string(n) + " of " + std::to_string(d.cases) + " cases)");
  if (d.cases_with_other_warnings > 0)
    out.push_back(std::to_string(d.cases_with_other_warnings) +
                  " cases have further warnings (the warnings column of results.csv)");
  return out;
}

std::string csv_field(const std::string& value) {
  if (value.find_first_of(",\"\n\r") == std::string::npos) return value;
  std::string out = "\"";
  for (char c : value) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

ResultsWriter::ResultsWriter(const Study& s, const fs::path& dir)
    : s_(s),
      partial_(dir / "results.csv.partial"),
      final_(dir / "results.csv"),
      params_(varied_keys(s)),
      metrics_(sim::summary_metric_names()) {
  for (const std::string& f : sim::summary_flag_names()) metrics_.push_back(f);  // 1 true, 0 false
  out_.open(partial_, std::ios::binary | std::ios::trunc);
  if (!out_) throw std::runtime_error(partial_.string() + ": cannot write");
  out_ << "case,controller,family,point,draw,hash";
  for (const std::string& p : params_) out_ << ',' << csv_field(p);
  out_ << ",ok,error,move_finished,warnings";
  for (const std::string& m : metrics_) out_ << ',' << csv_field(m);
  out_ << '\n';
}

ResultsWriter::~ResultsWriter() {
  if (done_) return;
  out_.close();
  std::error_code ec;
  fs::remove(partial_, ec);
}

void ResultsWriter::add(std::size_t index, const CaseRecord& c) {
  out_ << index << ',' << csv_field(s_.controllers[c.spec.controller].name) << ','
       << csv_field(s_.families[c.spec.family].name) << ',' << c.spec.point << ','
       << (c.spec.draw >= 0 ? std::to_string(c.spec.draw) : "") << ',' << c.resolved.hash.substr(0, 16);
  for (const std::string& p : params_) {
    const auto it = c.resolved.parameters.find(p);
    out_ << ',' << (it == c.resolved.parameters.end() ? "" : csv_field(it->second));
  }
  out_ << ',' << (c.outcome.ok ? "true" : "false") << ',' << csv_field(c.outcome.error) << ','
       << (c.outcome.move_finished ? (*c.outcome.move_finished ? "true" : "false") : "");
  std::string warnings;
  for (const std::string& w : c.outcome.warnings) warnings += (warnings.empty() ? "" : "; ") + w;
  out_ << ',' << csv_field(warnings);
  for (const std::string& m : metrics_) {
    out_ << ',';
    for (const auto& [k, v] : c.outcome.metrics)
      if (k == m) out_ << output::number_text(v);
  }
  out_ << '\n';
  if (!out_) throw std::runtime_error(partial_.string() + ": write failed");
}

void ResultsWriter::finish() {
  out_.close();
  if (!out_) throw std::runtime_error(partial_.string() + ": write failed");
  if (::rename(partial_.c_str(), final_.c_str()) != 0)
    throw std::runtime_error(final_.string() + ": cannot rename into place");
  done_ = true;
}

bool verdicts_hold(const Study& s, const Outcome& o) {
  for (const std::string& r : s.report.require) {
    if (r == "move_finished") {  // Outcome::move_finished: a case without a move does not pass it
      if (!o.move_finished.value_or(false)) return false;
      continue;
    }
    bool found = false;
    for (const auto& [k, v] : o.metrics)
      if (k == r) {
        found = true;
        if (v != 1.0) return false;
      }
    if (!found) return false;
  }
  return true;
}

bool case_passes(const Study& s, const Outcome& o, double shown) {
  if (!o.ok || std::isnan(shown)) return false;
  if (!std::isnan(s.report.limit) && shown > s.report.limit) return false;
  return verdicts_hold(s, o);
}

namespace {

// One case's control-signal figures into its controller's Signal (ReportData::Signal).
void add_signal(ReportData::Signal& sig, const Outcome& o) {
  bool verdict_found = false;
  for (std::size_t k = 0; k < ReportData::kSignalFigures.size(); ++k) {
    double x = NAN;
    for (const auto& [key, value] : o.metrics)
      if (key == ReportData::kSignalFigures[k]) x = value;
    if (!o.ok || std::isnan(x)) {
      ++sig.no_value[k];
    } else if (std::isnan(sig.worst[k]) || x > sig.worst[k]) {
      sig.worst[k] = x;
    }
  }
  for (const auto& [key, value] : o.metrics)
    if (o.ok && key == "control_signal_within_limits") {
      verdict_found = true;
      (value == 1.0 ? sig.within : sig.outside) += 1;
    }
  if (!verdict_found) ++sig.unknown;
}

}  // namespace

ReportData::ReportData(const Study& st)
    : s(st),
      params(varied_keys(st)),
      table(st.families.size(), std::vector<Cell>(st.controllers.size())),
      worst(st.controllers.size()),
      signal(st.controllers.size()),
      categories(params.size()) {
  const auto n = static_cast<std::size_t>(st.total_cases());  // exact: no doubling of the largest vectors
  controller.reserve(n);
  shown.reserve(n);
  x.reserve(n * params.size());
  category.reserve(n * params.size());
}

void ReportData::add(std::size_t index, const CaseRecord& c) {
  ++cases;
  failed += c.outcome.ok ? 0 : 1;
  cached += c.cached ? 1 : 0;
  const double v = shown_metric(s, c.outcome);
  Cell& cell_of = table[c.spec.family][c.spec.controller];
  ++cell_of.total;
  cell_of.passed += case_passes(s, c.outcome, v) ? 1 : 0;
  cell_of.verdict_failed += c.outcome.ok && !verdicts_hold(s, c.outcome) ? 1 : 0;
  if (!c.outcome.ok) {
    ++cell_of.failed;
    if (failures.size() < kListedFailures)
      failures.push_back({index, c.spec.controller, c.spec.family, c.outcome.error});
  } else if (std::isnan(v)) {
    ++cell_of.no_value;
  } else {
    cell_of.values.push_back(v);
    Worst& w = worst[c.spec.controller];
    if (!w.any || v > w.value) w = {true, index, c.spec.family, v, c.resolved.parameters};
  }
  add_signal(signal[c.spec.controller], c.outcome);
  controller.push_back(static_cast<std::uint32_t>(c.spec.controller));
  shown.push_back(v);
  for (std::size_t p = 0; p < params.size(); ++p) {
    const auto it = c.resolved.parameters.find(params[p]);
    double px = NAN;
    std::int16_t index = -1;
    if (it != c.resolved.parameters.end()) {
      if (!parse_number(it->second, px)) {
        px = NAN;
        categories[p].text = !it->second.empty() || categories[p].text;
      }
      Categories& cat = categories[p];
      const auto found = std::find(cat.values.begin(), cat.values.end(), it->second);
      if (found != cat.values.end()) {
        index = static_cast<std::int16_t>(found - cat.values.begin());
      } else if (cat.values.size() < kMaxCategories) {
        index = static_cast<std::int16_t>(cat.values.size());
        cat.values.push_back(it->second);
      } else {
        cat.more = true;
      }
    }
    x.push_back(static_cast<float>(px));
    category.push_back(index);
  }
  if (c.outcome.move_finished) {
    ++moves;
    moves_unfinished += *c.outcome.move_finished ? 0 : 1;
  }
  bool other = false;
  for (const std::string& w : c.outcome.warnings) {
    if (auto it = warnings.find(w); it != warnings.end()) {
      ++it->second;
    } else if (warnings.size() < kListedWarnings) {
      warnings.emplace(w, 1);
    } else {
      other = true;
    }
  }
  cases_with_other_warnings += other ? 1 : 0;
}

namespace {

// The gnuplot script and the markdown that write_plots builds, plot by plot.
struct PlotScript {
  std::ostringstream gp, md;
  std::string ylabel;      // the metric's axis label, a gnuplot string
  std::string limit_line;  // the report's limit as a dashed line, or ""
};

// Box plots: one box per family and controller, grouped by family; each box's values (> 0, the
// log axis) in box_<family>_<controller>.dat.
void box_plot(const fs::path& dir, const std::string& prefix, const ReportData& d, PlotScript& ps) {
  const Study& s = d.s;
  const std::size_t nc = s.controllers.size(), nf = s.families.size();
  const auto& t = d.table;
  std::vector<std::string> items;
  const double width = 0.8 / static_cast<double>(nc);
  for (std::size_t f = 0; f < nf; ++f) {
    for (std::size_t c = 0; c < nc; ++c) {
      std::ostringstream data;
      long n = 0;
      for (double v : t[f][c].values)
        if (v > 0.0) {
          data << output::number_text(v) << '\n';
          ++n;
        }
      if (n == 0) continue;
      const std::string file = "box_" + std::to_string(f) + "_" + std::to_string(c) + ".dat";
      output::write_file_atomically(dir / file, data.str());
      const double x =
          static_cast<double>(f + 1) + (static_cast<double>(c) - 0.5 * static_cast<double>(nc - 1)) * width;
      items.push_back("'" + file + "' using (" + output::number_text(x) + "):1:(" + output::number_text(0.9 * width) +
                      ") with boxplot linecolor " + std::to_string(c + 1) + " notitle");
    }
  }
  if (items.empty()) return;
  std::ostringstream& gp = ps.gp;
  gp << "set output 'box.png'\nset title "
     << output::gnuplot_string(s.name + ": " + s.report.metric + " per family and controller") << "\nset ylabel "
     << ps.ylabel << "\nset style fill solid 0.35 border -1\nset style boxplot outliers pointtype 7\n"
     << "set xrange [0.4:" << output::number_text(static_cast<double>(nf) + 0.6) << "]\nset xtics (";
  for (std::size_t f = 0; f < nf; ++f)
    gp << (f ? ", " : "") << output::gnuplot_string(s.families[f].name, 40) << ' ' << f + 1;
  gp << ") rotate by -25\n" << ps.limit_line << "plot ";
  for (std::size_t i = 0; i < items.size(); ++i) gp << (i ? ", \\\n  " : "") << items[i];
  // Legend entries: one invisible point per controller.
  for (std::size_t c = 0; c < nc; ++c)
    gp << ", \\\n  NaN with boxes linecolor " << c + 1 << " title "
       << output::gnuplot_string(s.controllers[c].name, 60);
  gp << "\nunset xtics\nset xtics\nunset xrange\nset autoscale x\n";
  ps.md << "![" << cell(s.report.metric) << " per family and controller](" << prefix << "box.png)\n\n";
}

// The data of the metric against varied key p, one file param_<p>_<controller>.dat per
// controller with a positive value; returns the series' plot clauses and adds their x to xs.
std::vector<std::string> param_series(const fs::path& dir, const ReportData& d, std::size_t p, const AxisUnit& ax,
                                      bool categorical, std::vector<double>& xs) {
  const Study& s = d.s;
  const std::size_t np = d.params.size();
  std::vector<std::string> series;
  for (std::size_t c = 0; c < s.controllers.size(); ++c) {
    std::ostringstream data;
    long n = 0;
    for (std::size_t i = 0; i < d.cases; ++i) {
      if (d.controller[i] != c) continue;
      const std::int16_t k = d.category[i * np + p];
      const double x = categorical ? (k >= 0 ? k + 1.0 : NAN) : d.x[i * np + p] * ax.factor, y = d.shown[i];
      if (!std::isfinite(x) || !(y > 0.0)) continue;
      xs.push_back(x);
      data << output::number_text(x) << ' ' << output::number_text(y) << '\n';
      ++n;
    }
    if (n == 0) continue;
    const std::string file = "param_" + std::to_string(p) + "_" + std::to_string(c) + ".dat";
    output::write_file_atomically(dir / file, data.str());
    series.push_back("'" + file + "' using 1:2 with points pointtype 7 pointsize 0.8 linecolor " +
                     std::to_string(c + 1) + " title " + output::gnuplot_string(s.controllers[c].name, 60));
  }
  return series;
}

// The metric against varied key p, one series per controller. A key whose values are not all
// numbers (switching: sgn, tanh) has one category per value on the x-axis, at 1, 2, ... in the
// order given.
void param_plot(const fs::path& dir, const std::string& prefix, const ReportData& d, std::size_t p, PlotScript& ps) {
  const Study& s = d.s;
  const std::vector<std::string>& params = d.params;
  const AxisUnit ax = axis_unit(params[p], d.x, params.size(), p);
  const bool categorical = is_categorical(d, p);
  std::vector<double> xs;
  const std::vector<std::string> series = param_series(dir, d, p, ax, categorical, xs);
  if (series.empty()) return;
  std::ostringstream& gp = ps.gp;
  const std::string png = "param_" + std::to_string(p) + ".png";
  gp << "set output '" << png << "'\nset title " << output::gnuplot_string(s.report.metric + " against " + params[p])
     << "\nset xlabel " << output::gnuplot_string(categorical ? params[p] : axis_label(params[p], ax))
     << "\nset ylabel " << ps.ylabel << "\nset xtics rotate by 0\n";
  const bool logx = !categorical && log_axis(s, params[p], xs);
  if (categorical) {
    const auto& values = d.categories[p].values;
    gp << "set xrange [0.5:" << output::number_text(static_cast<double>(values.size()) + 0.5) << "]\nset xtics (";
    for (std::size_t k = 0; k < values.size(); ++k)
      gp << (k ? ", " : "") << output::gnuplot_string(values[k], 40) << ' ' << k + 1;
    gp << ")\n";
  } else if (logx) {
    gp << "set logscale x\n";
  }
  gp << ps.limit_line << "plot ";
  for (std::size_t i = 0; i < series.size(); ++i) gp << (i ? ", \\\n  " : "") << series[i];
  gp << '\n';
  if (categorical) gp << "unset xtics\nset xtics\nunset xrange\nset autoscale x\n";
  if (logx) gp << "unset logscale x\n";
  ps.md << "![" << cell(s.report.metric) << " against " << cell(params[p]) << "](" << prefix << png << ")\n\n";
}

}  // namespace

std::string write_plots(const fs::path& dir, const std::string& prefix, const ReportData& d,
                        const interrupt::StopToken& stop) {
  const Study& s = d.s;
  fs::create_directories(dir);
  PlotScript ps;
  ps.ylabel = output::gnuplot_string(metric_label(s.report.metric, s.report.unit));
  ps.gp << "set encoding utf8\nset terminal pngcairo size 1200,650 noenhanced\nset grid ytics\n"
        << "set key outside top center horizontal\nset logscale y\n";
  if (!std::isnan(s.report.limit))
    ps.limit_line = "set arrow 1 from graph 0, first " + output::number_text(s.report.limit) + " to graph 1, first " +
                    output::number_text(s.report.limit) + " nohead dashtype 2 linewidth 2 linecolor rgb 'red'\n";
  box_plot(dir, prefix, d, ps);
  for (std::size_t p = 0; p < d.params.size(); ++p) param_plot(dir, prefix, d, p, ps);
  if (ps.md.str().empty()) return "No plot: no case gave a positive " + s.report.metric + ".\n\n";
  output::run_gnuplot(dir, ps.gp.str(), stop);
  return ps.md.str();
}

// For every varied key with at most kMaxRows distinct values: the metric's median per value and
// controller, the value in the key's engineering unit; a key with values that are not numbers
// (switching: sgn, tanh) by its values as written, in the order given.
std::string metric_by_value(const ReportData& d) {
  constexpr std::size_t kMaxRows = 50;
  const Study& s = d.s;
  const std::size_t nc = s.controllers.size(), np = d.params.size();
  std::ostringstream md;
  for (std::size_t p = 0; p < np; ++p) {
    const AxisUnit ax = axis_unit(d.params[p], d.x, np, p);
    const bool categorical = is_categorical(d, p);
    // row -> controller -> shown; a row is a value (numeric: sorted) or a category's index.
    std::map<double, std::vector<std::vector<double>>> rows;
    std::map<double, std::vector<long>> counts;  // row -> controller -> cases with that value
    for (std::size_t i = 0; i < d.cases; ++i) {
      const std::int16_t k = d.category[i * np + p];
      const double x = categorical ? (k >= 0 ? k : NAN) : d.x[i * np + p];
      if (!std::isfinite(x)) continue;
      auto& r = rows[x];
      r.resize(nc);
      auto& n = counts[x];
      n.resize(nc);
      ++n[d.controller[i]];
      if (std::isfinite(d.shown[i])) r[d.controller[i]].push_back(d.shown[i]);
    }
    md << "\n## " << cell(s.report.metric) << " against " << cell(d.params[p]) << "\n\n";
    if (rows.empty() || rows.size() > kMaxRows) {
      md << (d.categories[p].text && d.categories[p].more
                 ? "More than 50 values that are not all numbers: see results.csv.\n"
             : rows.empty() ? "No value of this key in any case.\n"
                            : "More than 50 values (a distribution): see its plot.\n");
      continue;
    }
    md << "| " << cell(categorical ? d.params[p] : axis_label(d.params[p], ax)) << " |";
    for (std::size_t c = 0; c < nc; ++c) md << " " << cell(s.controllers[c].name) << " [" << s.report.unit << "] |";
    md << "\n|---|";
    for (std::size_t c = 0; c < nc; ++c) md << "---|";
    md << "\n";
    long fewest = -1, most = 0;
    for (const auto& [x, per] : rows) {
      md << "| " << (categorical ? cell(d.categories[p].values[static_cast<std::size_t>(x)]) : num(x * ax.factor))
         << " |";
      for (std::size_t c = 0; c < nc; ++c) {
        md << " " << num(per[c].empty() ? NAN : median(per[c])) << " |";
        const long n = counts[x][c];
        if (n == 0) continue;
        fewest = fewest < 0 ? n : std::min(fewest, n);
        most = std::max(most, n);
      }
      md << "\n";
    }
    if (most <= 1) {
      md << "\nOne case per value and controller.\n";
    } else {
      md << "\nThe median over the cases with that value and controller ("
         << (fewest == most ? std::to_string(most) : std::to_string(fewest) + " to " + std::to_string(most))
         << " each, over the values of the other varied keys and the draws).\n";
    }
  }
  return md.str();
}

namespace {

// report.md's head: the title, the command, the case counts, unfinished moves, the loader's
// warnings and the model rule.
void md_head(std::ostringstream& md, const ReportData& d, const std::string& command) {
  const Study& s = d.s;
  md << "# Study: " << cell(s.name) << "\n\n"
     << "Written by `feeddrive-study`. Command:\n\n```bash\n"
     << command << "\n```\n\n"
     << d.cases << " cases (" << s.controllers.size() << " controllers x " << s.families.size() << " families), "
     << d.failed << " failed, " << d.cached << " reused from an earlier run into this folder. Every number below is "
     << "`" << s.report.metric << "` in " << s.report.unit << " (one row per case in `results.csv`).\n\n";
  // A move cut off by `duration` has errors of part of the move only (issue 23).
  if (d.moves_unfinished > 0)
    md << "**" << d.moves_unfinished << " of " << d.moves << " cases did not finish their move** within `duration` "
       << "(`move_finished` false in `results.csv`): their errors cover only the part of the move that ran.\n\n";
  if (const std::vector<std::string> lines = warning_lines(d); !lines.empty()) {
    md << "## Warnings\n\nThe scenario loader's warnings (an implausible value and its likely unit, a move cut off), "
          "once each with the number of cases that have it:\n\n";
    for (const std::string& l : lines) md << "- " << cell(l) << "\n";
    md << "\n";
  }
  md << (s.model == ModelRule::kNominal
             ? "The controllers keep the **nominal model** (`model: nominal`): a case's `plant.*` variations (except "
               "`plant.sensor.*`) change the drive, not the controller's model of it.\n\n"
             : "Each controller's model **follows the varied plant** (`model: follows_plant`): every result is a "
               "perfect-model result unless `controller.model.*` says otherwise.\n\n");
}

// "## Worst case per controller": per controller, the worst and the median over every family,
// with the cases over the limit and the cases that pass when the report has them.
void md_worst_per_controller(std::ostringstream& md, const ReportData& d) {
  const Study& s = d.s;
  const std::string& unit = s.report.unit;
  const bool limit = !std::isnan(s.report.limit), criterion = s.report.has_criterion();
  md << "## Worst case per controller\n\n| controller | cases | failed | worst [" << unit
     << "] | family of the worst | median [" << unit << "] |";
  if (limit) md << " over " << num(s.report.limit) << " " << unit << " |";
  if (criterion) md << " pass |";
  md << "\n|---|---|---|---|---|---|" << (limit ? "---|" : "") << (criterion ? "---|" : "") << "\n";
  for (std::size_t c = 0; c < s.controllers.size(); ++c) {
    std::vector<double> all;
    long total = 0, fail = 0, over = 0, passed = 0;
    double worst = NAN;
    std::string worst_family = "–";
    for (std::size_t f = 0; f < s.families.size(); ++f) {
      const Cell& x = d.table[f][c];
      total += x.total;
      fail += x.failed;
      passed += x.passed;
      for (double v : x.values) {
        all.push_back(v);
        if (limit && v > s.report.limit) ++over;
        if (std::isnan(worst) || v > worst) {
          worst = v;
          worst_family = s.families[f].name;
        }
      }
    }
    md << "| " << cell(s.controllers[c].name) << " | " << total << " | " << fail << " | " << num(worst) << " | "
       << cell(worst_family) << " | " << num(median(all)) << " |";
    if (limit) md << " " << over + fail << (over + fail == 0 ? " (meets the limit in every case)" : "") << " |";
    if (criterion)
      md << " " << (passed == total ? "**" : "") << passed << " of " << total << (passed == total ? "**" : "") << " |";
    md << "\n";
  }
  if (limit) md << "\nA failed case counts as over the limit (" << num(s.report.limit) << " " << unit << ").\n";
  if (criterion) md << "\n" << criterion_text(s) << "\n";
}

// "## Control signal per controller": always, whatever the report's metric: the worst of each
// control-signal figure (docs/scenario.md, "Control-signal quality") and the cases within the
// signal limits (control_signal_within_limits true). A case without the verdict (failed, or an
// outcome of an older version) is counted apart: unknown is never within the limits.
void md_signal_per_controller(std::ostringstream& md, const ReportData& d) {
  const Study& s = d.s;
  md << "\n## Control signal per controller\n\nThe worst (largest) of each control-signal figure over the "
        "controller's cases (docs/scenario.md, \"Control-signal quality\"), and the cases whose command is within "
        "every signal limit (`control_signal_within_limits`). Bold: not every case is within the limits.\n\n"
        "| controller | within the signal limits |";
  for (const char* k : ReportData::kSignalFigures) md << " worst `" << k << "` |";
  md << "\n|---|---|---|---|---|---|\n";
  for (std::size_t c = 0; c < s.controllers.size(); ++c) {
    const ReportData::Signal& g = d.signal[c];
    const long total = g.within + g.outside + g.unknown;
    const bool all = g.within == total;
    md << "| " << cell(s.controllers[c].name) << " | " << (all ? "" : "**") << g.within << " of " << total
       << (all ? "" : "**");
    if (g.unknown) md << " (" << g.unknown << " without the verdict)";
    md << " |";
    for (std::size_t k = 0; k < ReportData::kSignalFigures.size(); ++k) {
      md << " " << num(g.worst[k]);
      if (g.no_value[k]) md << " (" << g.no_value[k] << " without a value)";
      md << " |";
    }
    md << "\n";
  }
}

// The head of a table with one row per family and one column per controller.
void md_family_table_head(std::ostringstream& md, const Study& s) {
  md << "| family |";
  for (const ControllerEntry& c : s.controllers) md << " " << cell(c.name) << " |";
  md << "\n|---|";
  for (std::size_t c = 0; c < s.controllers.size(); ++c) md << "---|";
  md << "\n";
}

// A table of the worst (or the median) per family and controller, bold over the limit.
void md_family_table(std::ostringstream& md, const ReportData& d, const std::string& title, bool worst) {
  const Study& s = d.s;
  md << "\n## " << title << "\n\n";
  md_family_table_head(md, s);
  for (std::size_t f = 0; f < s.families.size(); ++f) {
    md << "| " << cell(s.families[f].name) << " (" << s.family_cases(f) << ") |";
    for (std::size_t c = 0; c < s.controllers.size(); ++c) {
      const Cell& x = d.table[f][c];
      double v = worst ? NAN : median(x.values);
      if (worst)
        for (double y : x.values) v = std::isnan(v) ? y : std::max(v, y);
      const bool over = !std::isnan(s.report.limit) && (v > s.report.limit || x.failed > 0);
      md << " " << (over ? "**" : "") << num(v) << (over ? "**" : "");
      if (x.failed) md << " (" << x.failed << " failed)";
      if (x.no_value) md << " (" << x.no_value << " without a value)";
      md << " |";
    }
    md << "\n";
  }
}

// "## Cases that pass per family" (a report with a limit or required verdicts).
void md_passes_per_family(std::ostringstream& md, const ReportData& d) {
  const Study& s = d.s;
  md << "\n## Cases that pass per family\n\n" << criterion_text(s) << " Bold: not every case passes.\n\n";
  md_family_table_head(md, s);
  for (std::size_t f = 0; f < s.families.size(); ++f) {
    md << "| " << cell(s.families[f].name) << " |";
    for (std::size_t c = 0; c < s.controllers.size(); ++c) {
      const Cell& x = d.table[f][c];
      const bool all = x.passed == x.total;
      md << " " << (all ? "" : "**") << x.passed << " of " << x.total << (all ? "" : "**");
      if (!s.report.require.empty() && x.verdict_failed) md << " (" << x.verdict_failed << " fail a verdict)";
      md << " |";
    }
    md << "\n";
  }
}

// "## The worst case of each controller", with its parameters.
void md_worst_cases(std::ostringstream& md, const ReportData& d) {
  const Study& s = d.s;
  md << "\n## The worst case of each controller\n\n| controller | family | case | " << s.report.unit
     << " | parameters |\n|---|---|---|---|---|\n";
  for (std::size_t c = 0; c < s.controllers.size(); ++c) {
    const ReportData::Worst& w = d.worst[c];
    if (!w.any) continue;
    std::string params;
    for (const auto& [k, v] : w.parameters) params += (params.empty() ? "" : ", ") + k + " = " + v;
    md << "| " << cell(s.controllers[c].name) << " | " << cell(s.families[w.family].name) << " | " << w.index << " | "
       << num(w.value) << " | " << cell(params) << " |\n";
  }
}

// "## Failed cases": the first ones kept, with their errors.
void md_failures(std::ostringstream& md, const ReportData& d) {
  const Study& s = d.s;
  md << "## Failed cases\n\n| case | controller | family | error |\n|---|---|---|---|\n";
  for (const ReportData::Failure& f : d.failures)
    md << "| " << f.index << " | " << cell(s.controllers[f.controller].name) << " | " << cell(s.families[f.family].name)
       << " | " << cell(f.error) << " |\n";
  if (d.failed > d.failures.size())
    md << "\nThe first " << d.failures.size() << " of " << d.failed
       << " failed cases; `results.csv` lists every one (ok = false).\n";
  md << "\n";
}

}  // namespace

std::string report_md(const ReportData& d, const std::string& command, const std::string& plots_markdown) {
  const Study& s = d.s;
  const std::string& unit = s.report.unit;
  std::ostringstream md;
  md_head(md, d, command);
  md_worst_per_controller(md, d);
  md_signal_per_controller(md, d);
  md_family_table(md, d, "Worst case per family [" + unit + "]", true);
  if (!std::isnan(s.report.limit)) md << "\nBold: over " << num(s.report.limit) << " " << unit << " (or failed).\n";
  if (s.report.has_criterion()) md_passes_per_family(md, d);
  md_family_table(md, d, "Median per family [" + unit + "]", false);
  md_worst_cases(md, d);
  md << metric_by_value(d);
  md << "\n## Plots\n\n" << plots_markdown;
  if (d.failed > 0) md_failures(md, d);
  md << "Each case's complete scenario is `cases/<hash>.yaml` (the hash column of `results.csv` is its first 16 "
        "digits); "
        "`feeddrive-sim cases/<hash>.yaml --out DIR` reruns it alone.\n";
  return md.str();
}

}  // namespace feeddrive::study
