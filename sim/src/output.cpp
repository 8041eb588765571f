#include "feeddrive/sim/output.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "feeddrive/output/folder.hpp"
#include "feeddrive/output/gnuplot.hpp"

namespace feeddrive::sim {
namespace fs = std::filesystem;

void write_timeseries_csv(const std::string& path, const std::vector<Record>& records) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error(path + ": cannot open for writing");
  const auto& cols = record_columns();
  for (std::size_t c = 0; c < cols.size(); ++c) std::fprintf(f, c ? ",%s" : "%s", cols[c].c_str());
  std::fputc('\n', f);
  for (const Record& r : records) {
    const std::vector<double> v = record_values(r);
    for (std::size_t c = 0; c < v.size(); ++c) std::fprintf(f, c ? ",%.17g" : "%.17g", v[c]);
    std::fputc('\n', f);
  }
  const bool ok = std::ferror(f) == 0;
  if (std::fclose(f) != 0 || !ok) throw std::runtime_error(path + ": write failed");
}

namespace {
int column(const std::string& name) {
  const auto& cols = record_columns();
  for (std::size_t c = 0; c < cols.size(); ++c)
    if (cols[c] == name) return static_cast<int>(c) + 1;
  throw std::logic_error("no column " + name);
}
}  // namespace

void write_plots(const std::string& dir, const std::string& title) {
  // Fixed data file name, the title through the one escaping rule (feeddrive/output/gnuplot.hpp).
  const std::string t = output::gnuplot_string(title);
  std::ostringstream gp;
  auto c = [](const char* n) { return std::to_string(column(n)); };
  gp << "set encoding utf8\nset datafile separator ','\n"
     << "set terminal pngcairo size 1000,700 noenhanced\n"
     << "set grid\nset key outside top center horizontal\n"
     << "data = 'timeseries.csv'\n"
     << "set xlabel 't [s]'\n";
  gp << "set output 'position.png'\nset multiplot layout 2,1 title " << t << "\n"
     << "set ylabel 'position [mm]'\n"
     << "plot data every ::1 using " << c("t") << ":($" << c("xd") << "*1e3) with lines lw 2 title 'x_d',"
     << " '' every ::1 using " << c("t") << ":($" << c("x") << "*1e3) with lines title 'x'\n"
     << "set ylabel 'error x_d - x [um]'\n"
     << "plot data every ::1 using " << c("t") << ":(($" << c("xd") << "-$" << c("x")
     << ")*1e6) with lines title 'e'\nunset multiplot\n";
  gp << "set output 'velocity_error.png'\nset title " << t << "\nset ylabel 'velocity error v_d - v [um/s]'\n"
     << "plot data every ::1 using " << c("t") << ":(($" << c("vd") << "-$" << c("v")
     << ")*1e6) with lines title 'e_v'\n";
  gp << "set output 'control.png'\nset ylabel 'control input u [V]'\n"
     << "plot data every ::1 using " << c("t") << ":" << c("u") << " with lines title 'u'\n";
  gp << "set output 'forces.png'\nset ylabel 'force [N]'\n"
     << "plot data every ::1 using " << c("t") << ":" << c("f_friction") << " with lines title 'friction',"
     << " '' every ::1 using " << c("t") << ":" << c("f_ripple") << " with lines title 'ripple',"
     << " '' every ::1 using " << c("t") << ":" << c("f_grinding") << " with lines title 'grinding'\n";
  output::run_gnuplot(dir, gp.str());
}

void write_results(const std::string& out_dir, const RunResult& r, const Summary& sum, const Scenario& s,
                   bool plots, const std::string& extra_json, const std::string& tool,
                   const std::function<void(const std::string&)>& extra_files) {
  output::StagedFolder out(out_dir, tool);
  const fs::path tmp = out.dir();
  write_timeseries_csv((tmp / "timeseries.csv").string(), r.records);
  {
    std::ofstream js(tmp / "summary.json");
    js << summary_json(sum, s, extra_json);
    js.close();
    if (!js) throw std::runtime_error((tmp / "summary.json").string() + ": write failed");
  }
  if (plots) write_plots(tmp.string(), s.name);
  if (extra_files) extra_files(tmp.string());
  out.commit();
}

}  // namespace feeddrive::sim
