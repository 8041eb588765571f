#include "feeddrive/study/session.hpp"

#include "feeddrive/sim/scenario.hpp"

#include <fcntl.h>
#include <sched.h>
#include <sys/file.h>
#include <unistd.h>

#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "feeddrive/common/errors.hpp"
#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/study/cases.hpp"
#include "feeddrive/study/report.hpp"
#include "feeddrive/study/runner.hpp"
#include "feeddrive/study/spec.hpp"

namespace feeddrive::study {
namespace {

namespace fs = std::filesystem;
constexpr const char* kTool = "feeddrive-study";

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// "<index>\n<bytes>": the case index and its settings (pack_settings) or outcome JSON in one MPI message.
std::string pack(std::size_t index, const std::string& text) { return std::to_string(index) + "\n" + text; }
std::pair<std::size_t, std::string> unpack(const std::string& m) {
  const std::size_t nl = m.find('\n');
  return {static_cast<std::size_t>(std::stoull(m.substr(0, nl))), m.substr(nl + 1)};
}

// Holds an exclusive lock on DIR/.feeddrive-study.lock while the study writes into DIR.
class FolderLock {
 public:
  explicit FolderLock(const fs::path& dir) {
    fd_ = ::open((dir / ".feeddrive-study.lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw std::runtime_error((dir / ".feeddrive-study.lock").string() + ": cannot open");
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd_);
      throw std::invalid_argument("--out " + dir.string() + ": another feeddrive-study is writing this folder");
    }
  }
  ~FolderLock() { ::close(fd_); }

 private:
  int fd_{-1};
};

// The study's output folder: reused if it is a feeddrive-study output, else made anew
// (replacing only an empty folder or another feeddrive output). `warnings`: the commit's.
fs::path prepare_folder(const std::string& out, std::vector<std::string>& warnings) {
  const fs::path dir = fs::absolute(output::check_output_dir(out));
  if (output::output_tool(dir) != kTool) {
    output::StagedFolder staged(out, kTool);
    fs::create_directories(staged.dir() / "cases");
    warnings = staged.commit(/*list_files=*/false);  // the study adds its cases and reports over reruns
  }
  fs::create_directories(dir / "cases");
  return dir;
}

}  // namespace

int available_cores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (::sched_getaffinity(0, sizeof set, &set) == 0) return std::max(1, CPU_COUNT(&set));
  return std::max(1u, std::thread::hardware_concurrency());
}

namespace {

// Worker threads running cases: the main thread hands each its index and the case's scenario, a
// struct (built from the case's settings on every rank: cases.hpp, CaseBuilder).
class CasePool {
 public:
  using Case = std::shared_ptr<const sim::Scenario>;
  CasePool(int jobs, const interrupt::StopToken& stop)
      : stop_(stop), pool_(jobs, [this](std::size_t i) { return run_case(*take(i), stop_); }) {}
  void push(std::size_t i, Case c) {
    {
      std::lock_guard<std::mutex> g(mu_);
      cases_[i] = std::move(c);
    }
    pool_.push(i);
  }
  std::size_t in_flight() const { return pool_.in_flight(); }
  std::optional<std::pair<std::size_t, Outcome>> pop(std::chrono::milliseconds wait) { return pool_.pop(wait); }

 private:
  Case take(std::size_t i) {
    std::lock_guard<std::mutex> g(mu_);
    Case c = std::move(cases_.at(i));
    cases_.erase(i);
    return c;
  }
  std::mutex mu_;
  std::map<std::size_t, Case> cases_;  // handed over, not yet taken by a thread
  const interrupt::StopToken stop_;
  Pool pool_;  // last: its threads stop before the map goes
};

// Cases resolved before any case runs (probe_cases): about 1 ms each, so the check takes about a
// second at most, and a 10^6-case study starts its first case within seconds.
constexpr std::size_t kProbeBudget = 1000;

// The exit of a Ctrl-C or SIGTERM: the other ranks told, then Interrupted with what was kept.
[[noreturn]] void throw_interrupted(Transport* t, int sig, const std::string& what) {
  if (t) t->abort(128 + sig);
  throw interrupt::Interrupted(sig, what);
}

// A case and what became of it, while it is between being handed out and its row.
struct Slot {
  CaseRecord record;
  bool finished{false};
};

// The study, its case count and its resolver, checked.
struct CheckedStudy {
  Study study;
  std::size_t total{0};
  std::unique_ptr<Resolver> resolver;
};

// Everything that can be wrong with the input, before any case runs: BadInput (exit 2), and the
// other ranks are told to stop. The cases are made and resolved one at a time as they are handed
// out (a study has up to 10^6: never all at once); here only the probe cases (cases.hpp) are
// resolved, so the usual mistakes still stop the study before it writes anything.
CheckedStudy check_study(const Options& o, Transport* t) {
  CheckedStudy c;
  try {
    if (o.sweeps.empty()) {
      c.study = load_study(o.study);
    } else {  // SCENARIO --sweep ...: a study without a study file
      std::vector<GridAxis> axes;
      for (const std::string& sw : o.sweeps) axes.push_back(parse_sweep(sw));
      c.study = sweep_study(o.study, axes);
    }
    // --set: settings of every case, after the study's own (as if its `set` ended with them).
    for (const std::string& k : o.sets) {
      const sim::KeySetting ks = sim::parse_key_setting(k);
      c.study.set.push_back({ks.key, ks.value});
    }
    if (!o.list) output::check_output_dir(o.out);
    c.total = case_count(c.study);
    c.resolver = std::make_unique<Resolver>(c.study);
    for (std::size_t i : probe_cases(c.study, kProbeBudget)) {
      o.stop.check();
      c.resolver->resolve(case_at(c.study, i));
    }
  } catch (const interrupt::Interrupted& e) {
    throw_interrupted(t, e.signal(), " while checking the study; nothing written");
  } catch (const std::exception& e) {
    if (t) t->broadcast(2);
    throw BadInput(e.what());
  }
  return c;
}

// --list: the resolved cases, one line each.
void list_cases(const CheckedStudy& c, const interrupt::StopToken& stop, Reporter& reporter) {
  // A case that does not resolve throws its typed error (StudyError, ScenarioError: bad input, exit
  // 2); any other error is the tool's own and reaches its exit code as such.
  reporter.listed(std::to_string(c.total) + " cases");
  for (std::size_t i = 0; i < c.total; ++i) {
    stop.check();
    const CaseSpec cs = case_at(c.study, i);
    const ResolvedCase r = c.resolver->resolve(cs);
    std::string line = std::to_string(i) + " " + r.hash.substr(0, 16) + " " + c.study.controllers[cs.controller].name +
                       " " + c.study.families[cs.family].name;
    // The parameters are keyed by the canonical spelling (varied_keys); the line shows the key as written.
    for (const auto& v : cs.variations) {
      const auto it = r.parameters.find(sim::canonical_key(v.key));
      line += " " + v.key + "=" + (it == r.parameters.end() ? std::string("?") : it->second);
    }
    reporter.listed(line);
  }
}

// The output folder, made or reused, and locked: BadInput for a folder that cannot be the
// study's (exit 2), a failure to write it (1); the other ranks are told either way.
struct LockedFolder {
  fs::path dir;
  std::unique_ptr<FolderLock> lock;
  std::vector<std::string> warnings;  // for the reporter
};
LockedFolder open_folder(const std::string& out, Transport* t) {
  LockedFolder f;
  try {
    f.dir = prepare_folder(out, f.warnings);
    f.lock = std::make_unique<FolderLock>(f.dir);
  } catch (const std::invalid_argument& e) {
    if (t) t->broadcast(2);
    throw BadInput(e.what());
  } catch (const std::exception& e) {
    if (t) t->broadcast(1);
    throw std::runtime_error(e.what());
  }
  return f;
}

// Streaming, in study order: case i is made (case_at), resolved and looked up in DIR/cases when
// it is handed out; its row goes to results.csv when every earlier case has its row. At most
// `window` cases are between being handed out and their row, so memory does not grow with the
// study (report.md keeps a few numbers per case: ReportData).
class CaseStream {
 public:
  CaseStream(const Options& o, Transport* t, const CheckedStudy& c, const fs::path& dir, int jobs, Reporter& reporter)
      : o_(o),
        t_(t),
        c_(c),
        dir_(dir),
        jobs_(jobs),
        reporter_(reporter),
        report_(c.study),
        window_(std::max<std::size_t>(
            256, 16 * static_cast<std::size_t>(jobs) * static_cast<std::size_t>(t ? t->size() : 1))) {}

  // Runs every case; throws Interrupted with what was kept (the other ranks told), or a failure.
  void run() {
    reporter_.progress_start(c_.total);
    try {
      results_ = std::make_unique<ResultsWriter>(c_.study, dir_);
      CasePool pool(jobs_, o_.stop);
      int released = 0;  // ranks told there is no more work
      while (next_row_ < c_.total || (t_ && released < t_->size() - 1)) {
        if (const int sig = o_.stop.signal()) stop(pool, sig);
        hand_out(pool, released);
        write_rows();
        if (pool.in_flight() > 0 || t_) {
          if (auto r = pool.pop(std::chrono::milliseconds(t_ ? 2 : 200))) record(r->first, std::move(r->second));
        }
        receive_from_ranks();
        write_rows();
      }
    } catch (const interrupt::Interrupted& e) {
      reporter_.progress_end();
      throw_interrupted(t_, e.signal(),
                        ": " + std::to_string(next_row_) + " of " + std::to_string(c_.total) +
                            " cases finished in order; run the same command to go on");
    } catch (const std::exception& e) {
      if (t_) t_->abort(1);
      throw std::runtime_error(e.what());
    }
    reporter_.progress_end();
  }

  ResultsWriter& results() { return *results_; }
  const ReportData& report() const { return report_; }
  std::size_t ran() const { return ran_; }
  std::size_t reused() const { return cached_; }
  std::size_t unresolved() const { return unresolved_; }
  double case_time() const { return case_time_; }

 private:
  // Ctrl-C or SIGTERM: the running cases stop at their next poll; what finished is kept.
  [[noreturn]] void stop(CasePool& pool, int sig) {
    while (pool.in_flight() > 0)
      if (auto r = pool.pop(std::chrono::milliseconds(100))) record(r->first, std::move(r->second));
    reporter_.progress_end();
    throw_interrupted(t_, sig,
                      ": " + std::to_string(next_row_) + " of " + std::to_string(c_.total) +
                          " cases finished in order (and every case run is kept in " + dir_.string() +
                          "/cases); run the same command to go on");
  }

  // Hands out cases in order, within the window, as long as a thread or a rank can take one.
  void hand_out(CasePool& pool, int& released) {
    const std::size_t want = static_cast<std::size_t>(jobs_) + waiting_.size() + (t_ ? 1 : 0);
    while (next_case_ < c_.total && next_case_ - next_row_ < window_ && ready_.size() < want &&
           !o_.stop.stop_requested())
      prepare_next();
    while (pool.in_flight() < static_cast<std::size_t>(jobs_) && !ready_.empty()) {
      pool.push(ready_.front(), slots_.at(ready_.front()).record.resolved.scenario);
      ready_.pop_front();
    }
    while (t_ && !waiting_.empty() && (!ready_.empty() || next_case_ == c_.total)) {
      const int rank = waiting_.front();
      waiting_.pop_front();
      if (ready_.empty()) {
        t_->send(rank, kAssign, "");
        ++released;
      } else {
        const std::size_t i = ready_.front();
        ready_.pop_front();
        t_->send(rank, kAssign, pack(i, pack_settings(slots_.at(i).record.resolved.settings)));
      }
    }
  }

  // The other ranks' requests and outcomes.
  void receive_from_ranks() {
    while (t_) {
      auto m = t_->poll();
      if (!m) break;
      if (m->tag == kRequest) {
        waiting_.push_back(m->from);
      } else if (m->tag == kResult) {
        auto [i, text] = unpack(m->payload);
        if (!slots_.count(i) || slots_.at(i).finished)
          throw std::runtime_error("rank " + std::to_string(m->from) + " sent an outcome for no case it was given");
        auto out = parse_outcome(text, "");  // the other ranks do not hash: the index names the case
        if (!out)
          throw std::runtime_error("rank " + std::to_string(m->from) + " sent a malformed outcome for case " +
                                   std::to_string(i));
        // The loader's warnings are those of the case as rank 0 built it (the struct).
        if (out->ok) out->warnings = slots_.at(i).record.resolved.scenario->warnings;
        record(i, std::move(*out));
      }
    }
  }

  void finished(std::size_t i, Outcome out) {
    Slot& sl = slots_.at(i);
    sl.record.outcome = std::move(out);
    sl.finished = true;
  }

  // Makes and resolves the next case: reused from DIR/cases, failed (it does not resolve), or ready.
  void prepare_next() {
    const std::size_t i = next_case_++;
    CaseRecord& c = slots_[i].record;
    c.spec = case_at(c_.study, i);
    try {
      c.resolved = c_.resolver->resolve(c.spec);
    } catch (const StudyError& e) {
      // Only a case the probes did not cover (another draw, another combination of axes) gets
      // here: a failed case in results.csv, like a run that fails (docs/study.md, Validation).
      Outcome out;
      out.error = e.what();
      ++unresolved_;
      for (const Variation& v :
           c.spec.variations)  // its row shows the values given (a factor has no nominal value here)
        if (!v.scale) c.resolved.parameters[sim::canonical_key(v.key)] = v.value;
      for (char& ch : out.error)
        if (ch == '\n' || ch == '\r') ch = ' ';
      finished(i, std::move(out));
      return;
    }
    const fs::path yaml = dir_ / "cases" / (c.resolved.hash + ".yaml");
    const fs::path json = dir_ / "cases" / (c.resolved.hash + ".json");
    std::error_code ec;
    if (fs::exists(json, ec)) {
      if (auto prev = parse_outcome(slurp(json), c.resolved.hash); prev && (prev->ok || !o_.retry_failed)) {
        c.cached = true;
        finished(i, std::move(*prev));
        return;
      }
    }
    if (!fs::exists(yaml, ec)) output::write_file_atomically(yaml, c.resolved.yaml);
    ready_.push_back(i);
  }

  // Writes the rows of the finished cases at the head of the study order.
  void write_rows() {
    for (auto it = slots_.begin(); it != slots_.end() && it->first == next_row_ && it->second.finished;
         it = slots_.erase(it)) {
      const CaseRecord& c = it->second.record;
      results_->add(it->first, c);
      report_.add(it->first, c);
      if (c.cached) ++cached_;
      reporter_.progress_step(c.cached, !c.cached && !c.outcome.ok);
      ++next_row_;
    }
  }

  void record(std::size_t i, Outcome out) {
    if (out.interrupted) return;  // not an outcome: the case runs again next time
    const Slot& sl = slots_.at(i);
    case_time_ += out.wall_s;
    ++ran_;
    output::write_file_atomically(dir_ / "cases" / (sl.record.resolved.hash + ".json"),
                                  outcome_json(sl.record.resolved.hash, out));
    finished(i, std::move(out));
  }

  const Options& o_;
  Transport* t_;
  const CheckedStudy& c_;
  const fs::path dir_;
  const int jobs_;
  Reporter& reporter_;
  ReportData report_;
  const std::size_t window_;
  std::unique_ptr<ResultsWriter> results_;
  std::map<std::size_t, Slot> slots_;  // handed out, row not yet written
  std::deque<std::size_t> ready_;      // resolved, to run
  std::deque<int> waiting_;            // ranks that asked for a case while none was ready
  std::size_t next_case_{0}, next_row_{0}, cached_{0}, ran_{0}, unresolved_{0};
  double case_time_{0.0};
};

// DIR/plots (replaced whole, never a moment without it); a failure to draw them is a warning:
// results.csv and report.md still go. Returns report.md's plot section.
std::string draw_plots(const Options& o, const fs::path& dir, const ReportData& report, Reporter& reporter) {
  if (!o.plots) return "Plots skipped (--no-plots).\n\n";
  const fs::path partial = dir / ".plots.partial";
  std::error_code ec;
  fs::remove_all(partial, ec);
  try {
    std::string md = write_plots(partial, "plots/", report, o.stop);
    output::replace_folder(partial, dir / "plots");
    return md;
  } catch (const interrupt::Interrupted&) {
    fs::remove_all(partial, ec);
    throw;
  } catch (const std::runtime_error& e) {
    fs::remove_all(partial, ec);
    reporter.warning("plots not drawn (" + std::string(e.what()) + "); the results are in " + dir.string());
    return "Plots not drawn: " + std::string(e.what()) + "\n\n";
  }
}

// results.csv closed, the plots, report.md and timing.json.
void write_report(const Options& o, Transport* t, const fs::path& dir, CaseStream& cases, std::size_t total, int jobs,
                  double wall_s, Reporter& reporter) {
  try {
    cases.results().finish();
    const std::string plots_md = draw_plots(o, dir, cases.report(), reporter);
    output::write_file_atomically(dir / "report.md", report_md(cases.report(), o.command, plots_md));
    nlohmann::ordered_json timing;
    timing["wall_s"] = wall_s;
    timing["cases"] = total;
    timing["cases_run"] = cases.ran();
    timing["cases_reused"] = cases.reused();
    timing["cases_not_resolved"] = cases.unresolved();  // failed before running: their scenario is invalid
    timing["case_time_sum_s"] = cases.case_time();
    timing["threads_per_rank"] = jobs;
    timing["ranks"] = t ? t->size() : 1;
    output::write_file_atomically(dir / "timing.json", timing.dump(2) + "\n");
  } catch (const interrupt::Interrupted& e) {
    throw_interrupted(
        t, e.signal(),
        ": every case finished and is kept in " + dir.string() + "/cases; run the same command to write the report");
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
}

}  // namespace

StudyResult run_study(const Options& o, Transport* t, Reporter& reporter) {
  const auto start = std::chrono::steady_clock::now();
  const CheckedStudy checked = check_study(o, t);
  StudyResult result;
  result.name = checked.study.name;
  result.total = checked.total;
  if (o.list) {
    if (t) t->broadcast(2);
    list_cases(checked, o.stop, reporter);
    return result;
  }
  const LockedFolder folder = open_folder(o.out, t);
  if (t) {
    t->broadcast(0);
    // What the other ranks build every case from (its settings come with each case): the base's
    // text and the controllers' blocks, once.
    const std::string bases = pack_bases(StudyBases::of(checked.study));
    for (int r = 1; r < t->size(); ++r) t->send(r, kBases, bases);
  }
  for (const std::string& w : folder.warnings) reporter.warning(w);
  const int jobs = o.jobs > 0 ? o.jobs : std::max(1, available_cores() / (t ? t->local_size() : 1));
  const int ranks = t ? t->size() : 1;
  reporter.started(checked.study.name + ": " + std::to_string(checked.total) + " cases on " + std::to_string(jobs) +
                   " thread" + (jobs == 1 ? "" : "s") + " x " + std::to_string(ranks) + " rank" +
                   (ranks == 1 ? "" : "s") + " -> " + folder.dir.string());
  CaseStream cases(o, t, checked, folder.dir, jobs, reporter);
  cases.run();
  write_report(o, t, folder.dir, cases, checked.total, jobs,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), reporter);
  result.ran = cases.ran();
  result.reused = cases.reused();
  result.failed = static_cast<std::size_t>(cases.report().failed);
  result.dir = folder.dir.string();
  result.warnings = warning_lines(cases.report());
  result.moves = cases.report().moves;
  result.moves_unfinished = cases.report().moves_unfinished;
  return result;
}

namespace {

// A rank's cases: built from the study's bases (sent once) and each case's settings, by the code
// that builds them on rank 0 (CaseBuilder); a case that does not build here is a failed case
// naming this rank (it built on rank 0), as are all of them if the bases do not.
class RankCases {
 public:
  RankCases(int rank, const std::string& bases) : rank_(rank) {
    try {
      builder_ = std::make_unique<CaseBuilder>(unpack_bases(bases));
    } catch (const std::exception& e) {
      error_ = e.what();
    }
  }
  // The case's scenario, or nullptr with `failed` its outcome.
  std::shared_ptr<const sim::Scenario> build(std::size_t index, const std::string& settings, Outcome& failed) {
    if (builder_) {
      try {
        return builder_->build(unpack_settings(settings), "case " + std::to_string(index));
      } catch (const std::exception& e) {
        failed.error = e.what();
      }
    } else {
      failed.error = error_;
    }
    failed.ok = false;
    failed.error = "rank " + std::to_string(rank_) + " could not build the case: " + failed.error;
    for (char& c : failed.error)
      if (c == '\n' || c == '\r') c = ' ';
    return nullptr;
  }

 private:
  int rank_;
  std::unique_ptr<CaseBuilder> builder_;
  std::string error_;
};

}  // namespace

int serve(Transport& t, int jobs, const interrupt::StopToken& stop) {
  const int status = t.broadcast(0);
  if (status != 0) return status;
  RankCases cases(t.rank(), t.receive(0).payload);  // kBases: the first message after the broadcast
  if (jobs <= 0) jobs = std::max(1, available_cores() / t.local_size());
  CasePool pool(jobs, stop);
  bool done = false;
  while (!done || pool.in_flight() > 0) {
    if (!done && pool.in_flight() < static_cast<std::size_t>(jobs)) {
      t.send(0, kRequest, "");
      const Message m = t.receive(0);
      if (m.payload.empty()) {
        done = true;
      } else {
        auto [i, settings] = unpack(m.payload);
        Outcome failed;
        if (auto scenario = cases.build(i, settings, failed)) {
          pool.push(i, std::move(scenario));
        } else {
          t.send(0, kResult, pack(i, outcome_json("", failed)));
        }
      }
      continue;
    }
    if (auto r = pool.pop(std::chrono::milliseconds(50))) {
      t.send(0, kResult, pack(r->first, outcome_json("", r->second)));
    }
  }
  return 0;
}

}  // namespace feeddrive::study
