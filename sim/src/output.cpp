#include "feeddrive/sim/output.hpp"

#include <sys/statvfs.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/common/validate.hpp"
#include "feeddrive/output/gnuplot.hpp"

namespace feeddrive::sim {
namespace fs = std::filesystem;

namespace {

// A size for a message: 290.49 GB, 2.1 MB, 512 kB (two decimals at most).
std::string size_text(double bytes) {
  const auto in = [&](double unit, const char* name) {
    return validate::format_number(std::round(bytes / unit * 100.0) / 100.0) + " " + name;
  };
  return bytes >= 1e9 ? in(1e9, "GB") : bytes >= 1e6 ? in(1e6, "MB") : in(1e3, "kB");
}

// The curves of the plots, computed from a record before the reduction (so the reduction keeps
// the extremes of exactly what is drawn).
// x_measured and e_m = xd - x_measured are drawn where the true state is missing (hardware).
enum Curve { kXd, kX, kE, kEv, kU, kFriction, kRipple, kGrinding, kXm, kEm, kCurves };
const std::vector<std::string>& curve_names() {
  static const std::vector<std::string> n = {"xd",         "x",        "e",          "e_v",        "u",
                                             "f_friction", "f_ripple", "f_grinding", "x_measured", "e_measured"};
  return n;
}
void curve_values(const Record& r, double* y) {
  y[kXd] = r.xd;
  y[kX] = r.x;
  y[kE] = r.xd - r.x;
  y[kEv] = r.vd - r.v;
  y[kU] = r.u;
  y[kFriction] = r.f_friction;
  y[kRipple] = r.f_ripple;
  y[kGrinding] = r.f_grinding;
  y[kXm] = r.x_measured;
  y[kEm] = r.xd - r.x_measured;
}

std::vector<std::size_t> column_indices(const Scenario& s) {
  const auto& all = record_columns();
  std::vector<std::size_t> idx;
  if (s.output.columns.empty()) {
    for (std::size_t c = 0; c < all.size(); ++c) idx.push_back(c);
    return idx;
  }
  for (const std::string& name : s.output.columns) {
    const auto it = std::find(all.begin(), all.end(), name);
    if (it == all.end()) throw std::invalid_argument("output.columns: unknown column '" + name + "'");
    idx.push_back(static_cast<std::size_t>(it - all.begin()));
  }
  return idx;
}

// The plot's time axis: the whole run [0, steps*T] (at least one period).
double plot_end(const Scenario& s) { return std::max(1.0, static_cast<double>(s.steps())) * s.control_period; }

}  // namespace

void check_run_size(const Scenario& s, const std::string& out_dir, double max_steps) {
  const double rows =
      std::ceil(std::min(static_cast<double>(s.steps()), max_steps) / static_cast<double>(s.output.every));
  const double cols = static_cast<double>(s.output.columns.empty() ? kRecordColumns : s.output.columns.size());
  const double least = rows * cols * 2.0;
  fs::path up = fs::absolute(output::normalise(out_dir));
  std::error_code ec;
  while (!fs::exists(up, ec) && up.has_relative_path()) up = up.parent_path();
  struct statvfs st {};
  if (::statvfs(up.c_str(), &st) != 0) return;  // unknown: the write itself reports a full disk
  const double free_bytes = static_cast<double>(st.f_bavail) * static_cast<double>(st.f_frsize);
  if (least > free_bytes) {
    throw std::invalid_argument(
        "duration, control_period, output.every, output.columns: timeseries.csv needs at least " + size_text(least) +
        " (" + validate::format_number(rows) + " rows x " + validate::format_number(cols) +
        " columns x 2 bytes), only " + size_text(free_bytes) + " free in " + up.string() +
        "; record fewer rows (output.every) or columns (output.columns)");
  }
}

RunWriter::RunWriter(const std::string& out_dir, const Scenario& s, const std::string& tool,
                     const interrupt::StopToken& stop)
    : s_(s),
      folder_(out_dir, tool),
      columns_(column_indices(s)),
      every_(s.output.every),
      expected_steps_(static_cast<double>(s.steps())),
      summary_(s),
      plot_(0.0, plot_end(s), kPlotBuckets, kCurves) {
  std::vector<std::string> header;
  for (std::size_t c : columns_) header.push_back(record_columns()[c]);
  csv_ = std::make_unique<output::CsvWriter>(folder_.path("timeseries.csv"), header);
  block_.reserve(kBlockRows);
  stop_token_ = stop;
  worker_ = std::thread([this] { work(); });
}

RunWriter::~RunWriter() {
  {
    std::lock_guard<std::mutex> lock(m_);
    stop_ = true;
  }
  cv_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void RunWriter::add(const Record& r) {
  block_.push_back(r);
  last_ = r;
  ++added_;
  if (block_.size() == kBlockRows) submit();
}

void RunWriter::submit() {
  if (block_.empty()) return;
  std::unique_lock<std::mutex> lock(m_);
  cv_.wait(lock, [this] { return queue_.size() < kQueuedBlocks || error_; });
  if (error_) std::rethrow_exception(error_);
  queue_.push_back(std::move(block_));
  if (!spare_.empty()) {
    block_ = std::move(spare_.back());
    spare_.pop_back();
  } else {
    block_ = {};
    block_.reserve(kBlockRows);
  }
  lock.unlock();
  cv_.notify_all();
}

void RunWriter::flush() {
  {
    std::lock_guard<std::mutex> lock(m_);
    if (error_) std::rethrow_exception(error_);
    flush_pending_ = true;
  }
  if (!block_.empty()) submit();
  cv_.notify_all();
}

void RunWriter::drain() {
  submit();
  std::unique_lock<std::mutex> lock(m_);
  cv_.wait(lock, [this] { return (queue_.empty() && !busy_ && !flush_pending_) || error_; });
  if (error_) std::rethrow_exception(error_);
}

void RunWriter::work() {
  std::unique_lock<std::mutex> lock(m_);
  for (;;) {
    cv_.wait(lock, [this] { return !queue_.empty() || stop_ || flush_pending_; });
    if (queue_.empty() && flush_pending_) {  // flush(): the rows written so far go to the file
      flush_pending_ = false;
      busy_ = true;
      lock.unlock();
      std::exception_ptr err;
      try {
        csv_->flush();
      } catch (...) {
        err = std::current_exception();
      }
      lock.lock();
      busy_ = false;
      if (err && !error_) error_ = err;
      cv_.notify_all();
      continue;
    }
    if (queue_.empty()) return;  // stop_
    std::vector<Record> rows = std::move(queue_.front());
    queue_.pop_front();
    busy_ = true;
    lock.unlock();
    cv_.notify_all();  // room in the queue
    std::exception_ptr err;
    try {
      for (const Record& r : rows) write(r);
    } catch (...) {
      err = std::current_exception();
    }
    rows.clear();
    lock.lock();
    busy_ = false;
    if (err && !error_) error_ = err;
    if (spare_.size() < kQueuedBlocks) spare_.push_back(std::move(rows));
    cv_.notify_all();
    if (error_) {
      queue_.clear();
      cv_.wait(lock, [this] { return stop_; });
      return;
    }
  }
}

void RunWriter::write(const Record& r) {
  // output.every keeps the rows of steps k = 0, N, 2N, ... by the step's own number, so a record
  // with gaps (a log, an attached monitor) keeps the same steps as a complete one.
  const double k = std::round(r.t / s_.control_period);
  if (every_ == 1 || std::fmod(k, static_cast<double>(every_)) == 0.0) {
    double all[kRecordColumns], row[kRecordColumns];
    record_values(r, all);
    for (std::size_t c = 0; c < columns_.size(); ++c) row[c] = all[columns_[c]];
    csv_->row(row, columns_.size());
    if (csv_->rows() == kProjectAfterRows) check_projected_size();
  }
  double y[kCurves];
  curve_values(r, y);
  plot_.add(r.t, y);
  summary_.add(r);
  ++written_;
}

void RunWriter::check_projected_size() const {
  // check_run_size's bound takes 2 bytes a value; the rows written so far say what the run's
  // values really take (about 12 bytes each in shortest round-trip form).
  const double rows_total = std::ceil(expected_steps_ / static_cast<double>(every_));
  const double per_row = static_cast<double>(csv_->bytes()) / static_cast<double>(csv_->rows());
  const double to_come = (rows_total - static_cast<double>(csv_->rows())) * per_row;
  struct statvfs st {};
  if (::statvfs(folder_.dir().c_str(), &st) != 0) return;  // unknown: the write itself reports a full disk
  const double free_bytes = static_cast<double>(st.f_bavail) * static_cast<double>(st.f_frsize);
  if (to_come > free_bytes) {
    throw std::invalid_argument(
        "duration, control_period, output.every, output.columns: timeseries.csv would take about " +
        size_text(to_come + static_cast<double>(csv_->bytes())) + " (" + validate::format_number(rows_total) +
        " rows of " + validate::format_number(std::round(per_row)) + " bytes, measured on the first " +
        std::to_string(kProjectAfterRows) + "), only " + size_text(free_bytes) + " free in " +
        folder_.target().parent_path().string() + "; record fewer rows (output.every) or columns (output.columns)");
  }
}

Summary RunWriter::summary(double wall_time_s, const std::optional<plant::CvodeIntegrator::Stats>& integrator) {
  drain();
  return summary_.summary(wall_time_s, integrator);
}

std::filesystem::path RunWriter::finish(const Summary& sum, bool plots, const std::string& extra_json,
                                        const std::function<void(const output::StagedFolder&)>& extra_files,
                                        bool replace_earlier) {
  drain();
  {
    std::lock_guard<std::mutex> lock(m_);
    stop_ = true;
  }
  cv_.notify_all();
  worker_.join();
  csv_->close();
  folder_.write_text("summary.json", summary_json(sum, s_, extra_json));
  if (plots && written_ > 0) {
    // The plots are a view of the data: if gnuplot fails, the run's files are still put in
    // place (plot_error() says why; an interrupt still ends the writing).
    const auto t0 = std::chrono::steady_clock::now();
    try {
      write_plots(folder_, plot_, s_.name, stop_token_);
    } catch (const interrupt::Interrupted& e) {
      // The interrupt flag stays set: the caller ends as interrupted once the data are in place.
      if (!keep_on_interrupt_) throw;
      plot_error_ = e.what();
    } catch (const std::runtime_error& e) {
      plot_error_ = e.what();
    }
    plot_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  if (extra_files) extra_files(folder_);
  if (!replace_earlier) return folder_.commit_keeping_earlier("incomplete");
  warnings_ = folder_.commit();
  return folder_.target();
}

void write_plots(const output::StagedFolder& dir, const output::MinMaxReducer& reduced, const std::string& title,
                 const interrupt::StopToken& stop) {
  reduced.write_csv(dir.path("plot.csv"), curve_names());
  // Curve c of plot.csv: time in column 2c+1, value in 2c+2 (MinMaxReducer::write_csv). A panel
  // draws only the curves with samples; one with none (a run without the true state, e.g. from
  // hardware) is an empty frame saying so: gnuplot refuses a plot with no point in range.
  struct Line {
    Curve c;
    const char* scale;
    const char* style;
    const char* title;
  };
  // A force that is 0 throughout (ripple or grinding switched off) is not drawn: a flat line at 0
  // titled "grinding" reads as a grinding force that happens to be 0.
  const auto zero_throughout = [&](Curve c) {
    for (std::size_t b = 0; b < reduced.buckets(); ++b) {
      const output::MinMaxReducer::Extremes& e = reduced.at(b, c);
      if (e.n > 0 && (e.y_min != 0.0 || e.y_max != 0.0)) return false;
    }
    return true;
  };
  auto panel = [&](const std::vector<Line>& lines, const char* none, bool skip_zero = false) {
    std::ostringstream p;
    bool first = true;
    for (const Line& l : lines) {
      if (!reduced.has_samples(l.c) || (skip_zero && zero_throughout(l.c))) continue;
      p << (first ? "plot data" : ", ''") << " every ::1 using " << 2 * l.c + 1 << ":($" << 2 * l.c + 2 << l.scale
        << ") with lines " << l.style << "title '" << l.title << "'";
      first = false;
    }
    if (first)
      return "set label 1 '" + std::string(none) +
             "' at graph 0.5,0.5 center\nplot [0:1][0:1] NaN notitle\nunset label 1\n";
    return p.str() + "\n";
  };
  // Fixed data file name, the title through the one escaping rule (feeddrive/output/gnuplot.hpp).
  const std::string t = output::gnuplot_string(title);
  // The true state where it exists (a simulated plant), else the measurement (hardware).
  const bool truth = reduced.has_samples(kX);
  std::ostringstream gp;
  gp << "data = 'plot.csv'\nset xlabel 't [s]'\nset autoscale xfix\n";  // the run's time span, not rounded to a tick
  gp << "set output 'position.png'\nset multiplot layout 2,1 title " << t << "\n"
     << "set ylabel 'position [mm]'\n"
     << (truth ? panel({{kXd, "*1e3", "lw 2 ", "x_d"}, {kX, "*1e3", "", "x"}}, "no position recorded")
               : panel({{kXd, "*1e3", "lw 2 ", "x_d"}, {kXm, "*1e3", "", "x_measured"}}, "no position recorded"))
     << (truth ? "set ylabel 'error x_d - x [um]'\n" : "set ylabel 'error x_d - x_measured [um]'\n")
     << (truth ? panel({{kE, "*1e6", "", "e"}}, "no error to draw")
               : panel({{kEm, "*1e6", "", "e (measured)"}}, "no position recorded: no error to draw"))
     << "unset multiplot\n";
  gp << "set output 'velocity_error.png'\nset title " << t << "\nset ylabel 'velocity error v_d - v [um/s]'\n"
     << panel({{kEv, "*1e6", "", "e_v"}}, "no true velocity: no error to draw");
  gp << "set output 'control.png'\nset ylabel 'control input u [V]'\n"
     << panel({{kU, "", "", "u"}}, "no command recorded");
  gp << "set output 'forces.png'\nset ylabel 'force [N]'\n"
     << panel({{kFriction, "", "", "friction"}, {kRipple, "", "", "ripple"}, {kGrinding, "", "", "grinding"}},
              "no friction, ripple or grinding force of the paper model in this run (forces of plant.effects are not "
              "drawn)",
              true);
  dir.plot(gp.str(), stop);
}

}  // namespace feeddrive::sim
