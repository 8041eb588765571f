#include "feeddrive/study/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "feeddrive/output/csv.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/output/gnuplot.hpp"

namespace feeddrive::study {
namespace {

namespace fs = std::filesystem;

// The metric of the report (scaled to its unit), NaN if the case failed or lacks it.
double shown_metric(const Study& s, const CaseRecord& c) {
  if (!c.outcome.ok) return NAN;
  for (const auto& [k, v] : c.outcome.metrics)
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

struct Cell {
  std::vector<double> values;
  long failed{0};    ///< cases that failed (ok = false)
  long no_value{0};  ///< cases that ran but have no value of the metric (e.g. a settled metric of a run shorter than settled_after)
  long total{0};
};

// values[family][controller]
std::vector<std::vector<Cell>> table(const Study& s, const std::vector<CaseRecord>& cases) {
  std::vector<std::vector<Cell>> t(s.families.size(), std::vector<Cell>(s.controllers.size()));
  for (const CaseRecord& c : cases) {
    Cell& x = t[c.spec.family][c.spec.controller];
    ++x.total;
    const double v = shown_metric(s, c);
    if (!c.outcome.ok) {
      ++x.failed;
    } else if (std::isnan(v)) {
      ++x.no_value;
    } else {
      x.values.push_back(v);
    }
  }
  return t;
}

bool parse_number(const std::string& text, double& out) {
  char* end = nullptr;
  out = std::strtod(text.c_str(), &end);
  return !text.empty() && end == text.c_str() + text.size() && std::isfinite(out);
}


}  // namespace

std::string csv_field(const std::string& value) {
  if (value.find_first_of(",\"\n\r") == std::string::npos) return value;
  std::string out = "\"";
  for (char c : value) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string results_csv(const Study& s, const std::vector<CaseRecord>& cases) {
  const std::vector<std::string> params = varied_keys(s);
  std::vector<std::string> metrics;
  for (const CaseRecord& c : cases) {
    if (!c.outcome.ok) continue;
    for (const auto& [k, v] : c.outcome.metrics) metrics.push_back(k);
    break;
  }
  std::ostringstream out;
  out << "case,controller,family,point,draw,hash";
  for (const std::string& p : params) out << ',' << csv_field(p);
  out << ",ok,error";
  for (const std::string& m : metrics) out << ',' << csv_field(m);
  out << '\n';
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const CaseRecord& c = cases[i];
    out << i << ',' << csv_field(s.controllers[c.spec.controller].name) << ',' << csv_field(s.families[c.spec.family].name)
        << ',' << c.spec.point << ',' << (c.spec.draw >= 0 ? std::to_string(c.spec.draw) : "") << ','
        << c.resolved.hash.substr(0, 16);
    for (const std::string& p : params) {
      const auto it = c.resolved.parameters.find(p);
      out << ',' << (it == c.resolved.parameters.end() ? "" : csv_field(it->second));
    }
    out << ',' << (c.outcome.ok ? "true" : "false") << ',' << csv_field(c.outcome.error);
    for (const std::string& m : metrics) {
      out << ',';
      for (const auto& [k, v] : c.outcome.metrics)
        if (k == m) out << output::number_text(v);
    }
    out << '\n';
  }
  return out.str();
}

std::string write_plots(const fs::path& dir, const std::string& prefix, const Study& s, const std::vector<CaseRecord>& cases) {
  fs::create_directories(dir);
  const std::size_t nc = s.controllers.size(), nf = s.families.size();
  const std::string ylabel = output::gnuplot_string(s.report.metric + " [" + s.report.unit + "]");
  std::ostringstream gp, md;
  gp << "set encoding utf8\nset terminal pngcairo size 1200,650 noenhanced\nset grid ytics\n"
     << "set key outside top center horizontal\nset logscale y\n";
  const std::string limit_line =
      std::isnan(s.report.limit)
          ? std::string()
          : "set arrow 1 from graph 0, first " + output::number_text(s.report.limit) + " to graph 1, first " +
                output::number_text(s.report.limit) + " nohead dashtype 2 linewidth 2 linecolor rgb 'red'\n";

  // Box plots: one box per family and controller, grouped by family.
  const auto t = table(s, cases);
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
      const double x = static_cast<double>(f + 1) + (static_cast<double>(c) - 0.5 * static_cast<double>(nc - 1)) * width;
      items.push_back("'" + file + "' using (" + output::number_text(x) + "):1:(" + output::number_text(0.9 * width) +
                      ") with boxplot linecolor " + std::to_string(c + 1) + " notitle");
    }
  }
  if (!items.empty()) {
    gp << "set output 'box.png'\nset title " << output::gnuplot_string(s.name + ": " + s.report.metric + " per family and controller")
       << "\nset ylabel " << ylabel << "\nset style fill solid 0.35 border -1\nset style boxplot outliers pointtype 7\n"
       << "set xrange [0.4:" << output::number_text(static_cast<double>(nf) + 0.6) << "]\nset xtics (";
    for (std::size_t f = 0; f < nf; ++f) gp << (f ? ", " : "") << output::gnuplot_string(s.families[f].name, 40) << ' ' << f + 1;
    gp << ") rotate by -25\n" << limit_line << "plot ";
    for (std::size_t i = 0; i < items.size(); ++i) gp << (i ? ", \\\n  " : "") << items[i];
    // Legend entries: one invisible point per controller.
    for (std::size_t c = 0; c < nc; ++c)
      gp << ", \\\n  NaN with boxes linecolor " << c + 1 << " title " << output::gnuplot_string(s.controllers[c].name, 60);
    gp << "\nunset xtics\nset xtics\nunset xrange\nset autoscale x\n";
    md << "![" << cell(s.report.metric) << " per family and controller](" << prefix << "box.png)\n\n";
  }

  // The metric against each varied parameter, one series per controller.
  const std::vector<std::string> params = varied_keys(s);
  for (std::size_t p = 0; p < params.size(); ++p) {
    std::vector<std::string> series;
    for (std::size_t c = 0; c < nc; ++c) {
      std::ostringstream data;
      long n = 0;
      for (const CaseRecord& r : cases) {
        if (r.spec.controller != c) continue;
        const auto it = r.resolved.parameters.find(params[p]);
        double x = 0.0;
        const double y = shown_metric(s, r);
        if (it == r.resolved.parameters.end() || !parse_number(it->second, x) || !(y > 0.0)) continue;
        data << output::number_text(x) << ' ' << output::number_text(y) << '\n';
        ++n;
      }
      if (n == 0) continue;
      const std::string file = "param_" + std::to_string(p) + "_" + std::to_string(c) + ".dat";
      output::write_file_atomically(dir / file, data.str());
      series.push_back("'" + file + "' using 1:2 with points pointtype 7 pointsize 0.8 linecolor " + std::to_string(c + 1) +
                       " title " + output::gnuplot_string(s.controllers[c].name, 60));
    }
    if (series.empty()) continue;
    const std::string png = "param_" + std::to_string(p) + ".png";
    gp << "set output '" << png << "'\nset title " << output::gnuplot_string(s.report.metric + " against " + params[p])
       << "\nset xlabel " << output::gnuplot_string(params[p]) << "\nset ylabel " << ylabel << "\nset xtics rotate by 0\n"
       << limit_line << "plot ";
    for (std::size_t i = 0; i < series.size(); ++i) gp << (i ? ", \\\n  " : "") << series[i];
    gp << '\n';
    md << "![" << cell(s.report.metric) << " against " << cell(params[p]) << "](" << prefix << png << ")\n\n";
  }
  if (md.str().empty()) return "No plot: no case gave a positive " + s.report.metric + ".\n\n";
  output::run_gnuplot(dir, gp.str());
  return md.str();
}

std::string report_md(const Study& s, const std::vector<CaseRecord>& cases, const std::string& command,
                      const std::string& plots_markdown) {
  std::ostringstream md;
  long failed = 0, cached = 0;
  for (const CaseRecord& c : cases) {
    failed += c.outcome.ok ? 0 : 1;
    cached += c.cached ? 1 : 0;
  }
  const std::string unit = s.report.unit;
  md << "# Study: " << cell(s.name) << "\n\n"
     << "Written by `feeddrive-study`. Command:\n\n```bash\n" << command << "\n```\n\n"
     << cases.size() << " cases (" << s.controllers.size() << " controllers x " << s.families.size() << " families), "
     << failed << " failed, " << cached << " reused from an earlier run into this folder. Every number below is "
     << "`" << s.report.metric << "` in " << unit << " (one row per case in `results.csv`).\n\n";

  const auto t = table(s, cases);
  const std::size_t nc = s.controllers.size();
  // Per controller: worst over everything.
  md << "## Worst case per controller\n\n| controller | cases | failed | worst [" << unit << "] | family of the worst | median ["
     << unit << "] |";
  if (!std::isnan(s.report.limit)) md << " over " << num(s.report.limit) << " " << unit << " |";
  md << "\n|---|---|---|---|---|---|" << (std::isnan(s.report.limit) ? "" : "---|") << "\n";
  for (std::size_t c = 0; c < nc; ++c) {
    std::vector<double> all;
    long total = 0, fail = 0, over = 0;
    double worst = NAN;
    std::string worst_family = "–";
    for (std::size_t f = 0; f < s.families.size(); ++f) {
      const Cell& x = t[f][c];
      total += x.total;
      fail += x.failed;
      for (double v : x.values) {
        all.push_back(v);
        if (!std::isnan(s.report.limit) && v > s.report.limit) ++over;
        if (std::isnan(worst) || v > worst) {
          worst = v;
          worst_family = s.families[f].name;
        }
      }
    }
    md << "| " << cell(s.controllers[c].name) << " | " << total << " | " << fail << " | " << num(worst) << " | "
       << cell(worst_family) << " | " << num(median(all)) << " |";
    if (!std::isnan(s.report.limit)) md << " " << over + fail << (over + fail == 0 ? " (meets the limit in every case)" : "") << " |";
    md << "\n";
  }
  if (!std::isnan(s.report.limit))
    md << "\nA failed case counts as over the limit (" << num(s.report.limit) << " " << unit << ").\n";

  const auto grid_table = [&](const char* title, bool worst) {
    md << "\n## " << title << "\n\n| family |";
    for (std::size_t c = 0; c < nc; ++c) md << " " << cell(s.controllers[c].name) << " |";
    md << "\n|---|";
    for (std::size_t c = 0; c < nc; ++c) md << "---|";
    md << "\n";
    for (std::size_t f = 0; f < s.families.size(); ++f) {
      md << "| " << cell(s.families[f].name) << " (" << s.family_cases(f) << ") |";
      for (std::size_t c = 0; c < nc; ++c) {
        const Cell& x = t[f][c];
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
  };
  grid_table(("Worst case per family [" + unit + "]").c_str(), true);
  if (!std::isnan(s.report.limit)) md << "\nBold: over " << num(s.report.limit) << " " << unit << " (or failed).\n";
  grid_table(("Median per family [" + unit + "]").c_str(), false);

  // The worst case of each controller, with its parameters.
  md << "\n## The worst case of each controller\n\n| controller | family | case | " << unit << " | parameters |\n|---|---|---|---|---|\n";
  for (std::size_t c = 0; c < nc; ++c) {
    const CaseRecord* w = nullptr;
    std::size_t wi = 0;
    for (std::size_t i = 0; i < cases.size(); ++i) {
      if (cases[i].spec.controller != c) continue;
      const double v = shown_metric(s, cases[i]);
      if (std::isnan(v)) continue;
      if (!w || v > shown_metric(s, *w)) {
        w = &cases[i];
        wi = i;
      }
    }
    if (!w) continue;
    std::string params;
    for (const auto& [k, v] : w->resolved.parameters) params += (params.empty() ? "" : ", ") + k + " = " + v;
    md << "| " << cell(s.controllers[c].name) << " | " << cell(s.families[w->spec.family].name) << " | " << wi << " | "
       << num(shown_metric(s, *w)) << " | " << cell(params) << " |\n";
  }

  md << "\n## Plots\n\n" << plots_markdown;
  if (failed > 0) {
    md << "## Failed cases\n\n| case | controller | family | error |\n|---|---|---|---|\n";
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const CaseRecord& c = cases[i];
      if (c.outcome.ok) continue;
      md << "| " << i << " | " << cell(s.controllers[c.spec.controller].name) << " | " << cell(s.families[c.spec.family].name)
         << " | " << cell(c.outcome.error) << " |\n";
    }
    md << "\n";
  }
  md << "Each case's complete scenario is `cases/<hash>.yaml` (the hash column of `results.csv` is its first 16 digits); "
        "`feeddrive-sim cases/<hash>.yaml --out DIR` reruns it alone.\n";
  return md.str();
}

}  // namespace feeddrive::study
