#include "feeddrive/study/session.hpp"

#include "feeddrive/sim/scenario.hpp"

#include <fcntl.h>
#include <sched.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

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

// "<index>\n<text>": the case index and its YAML or outcome JSON in one MPI message.
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
// (replacing only an empty folder or another feeddrive output).
fs::path prepare_folder(const std::string& out) {
  const fs::path dir = fs::absolute(output::check_output_dir(out));
  if (output::output_tool(dir) != kTool) {
    output::StagedFolder staged(out, kTool);
    fs::create_directories(staged.dir() / "cases");
    staged.commit(/*list_files=*/false);  // the study adds its cases and reports over reruns
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

// Worker threads running cases: the main thread hands each its index and scenario.
class CasePool {
 public:
  explicit CasePool(int jobs) : pool_(jobs, [this](std::size_t i) { return run_case(take(i)); }) {}
  void push(std::size_t i, std::string yaml) {
    {
      std::lock_guard<std::mutex> g(mu_);
      yaml_[i] = std::move(yaml);
    }
    pool_.push(i);
  }
  std::size_t in_flight() const { return pool_.in_flight(); }
  std::optional<std::pair<std::size_t, Outcome>> pop(std::chrono::milliseconds wait) { return pool_.pop(wait); }

 private:
  std::string take(std::size_t i) {
    std::lock_guard<std::mutex> g(mu_);
    std::string text = std::move(yaml_.at(i));
    yaml_.erase(i);
    return text;
  }
  std::mutex mu_;
  std::map<std::size_t, std::string> yaml_;  // handed over, not yet taken by a thread
  Pool pool_;                                // last: its threads stop before the map goes
};

// Cases resolved before any case runs (probe_cases): about 1 ms each, so the check takes about a
// second at most, and a 10^6-case study starts its first case within seconds.
constexpr std::size_t kProbeBudget = 1000;

// The exit of a Ctrl-C or SIGTERM: the message, the other ranks told, 128 + the signal.
int interrupted_exit(Transport* t, const std::string& what) {
  const int sig = interrupt::signal_number();
  std::fprintf(stderr, "interrupted by %s%s\n", interrupt::signal_name(sig).c_str(), what.c_str());
  if (t) t->abort(128 + sig);
  return 128 + sig;
}

// A case and what became of it, while it is between being handed out and its row.
struct Slot {
  CaseRecord record;
  bool finished{false};
};

}  // namespace

int run_study(const Options& o, Transport* t) {
  const auto start = std::chrono::steady_clock::now();
  Study study;
  std::size_t total = 0;
  std::unique_ptr<Resolver> resolver;
  fs::path dir;
  std::unique_ptr<FolderLock> lock;
  // Everything that can be wrong with the input, before any case runs: exit 2, and the other
  // ranks are told to stop. The cases are made and resolved one at a time as they are handed out
  // (a study has up to 10^6: never all at once); here only the probe cases (cases.hpp) are
  // resolved, so the usual mistakes still stop the study before it writes anything.
  try {
    if (o.sweeps.empty()) {
      study = load_study(o.study);
    } else {  // SCENARIO --sweep ...: a study without a study file
      std::vector<GridAxis> axes;
      for (const std::string& sw : o.sweeps) axes.push_back(parse_sweep(sw));
      study = sweep_study(o.study, axes);
    }
    // --set: settings of every case, after the study's own (as if its `set` ended with them).
    for (const std::string& k : o.sets) {
      const sim::KeySetting ks = sim::parse_key_setting(k);
      study.set.push_back({ks.key, ks.value});
    }
    if (!o.list) output::check_output_dir(o.out);
    total = case_count(study);
    resolver = std::make_unique<Resolver>(study);
    for (std::size_t i : probe_cases(study, kProbeBudget)) {
      interrupt::check();
      resolver->resolve(case_at(study, i));
    }
  } catch (const interrupt::Interrupted&) {
    return interrupted_exit(t, " while checking the study; nothing written");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    if (t) t->broadcast(2);
    return 2;
  }
  if (o.list) {
    if (t) t->broadcast(2);
    std::printf("%zu cases\n", total);
    try {
      for (std::size_t i = 0; i < total; ++i) {
        interrupt::check();
        const CaseSpec c = case_at(study, i);
        const ResolvedCase r = resolver->resolve(c);
        std::string params;
        for (const auto& v : c.variations) params += " " + v.key + "=" + r.parameters.at(v.key);
        std::printf("%zu %s %s %s%s\n", i, r.hash.substr(0, 16).c_str(), study.controllers[c.controller].name.c_str(),
                    study.families[c.family].name.c_str(), params.c_str());
      }
    } catch (const interrupt::Interrupted&) {
      std::fflush(stdout);
      return interrupted_exit(nullptr, "");
    } catch (const std::exception& e) {
      std::fflush(stdout);
      std::fprintf(stderr, "error: %s\n", e.what());
      return 2;
    }
    return 0;
  }
  try {
    dir = prepare_folder(o.out);
    lock = std::make_unique<FolderLock>(dir);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    if (t) t->broadcast(2);
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    if (t) t->broadcast(1);
    return 1;
  }
  if (t) t->broadcast(0);

  const int jobs = o.jobs > 0 ? o.jobs : std::max(1, available_cores() / (t ? t->local_size() : 1));
  const int ranks = t ? t->size() : 1;
  if (!o.quiet)
    std::fprintf(stderr, "%s: %zu cases on %d thread%s x %d rank%s -> %s\n", study.name.c_str(), total, jobs,
                 jobs == 1 ? "" : "s", ranks, ranks == 1 ? "" : "s", dir.c_str());

  // Streaming, in study order: case i is made (case_at), resolved and looked up in DIR/cases when
  // it is handed out; its row goes to results.csv when every earlier case has its row. At most
  // `window` cases are between being handed out and their row, so memory does not grow with the
  // study (report.md keeps a few numbers per case: ReportData).
  const std::size_t workers = static_cast<std::size_t>(jobs) * static_cast<std::size_t>(ranks);
  const std::size_t window = std::max<std::size_t>(256, 16 * workers);
  std::map<std::size_t, Slot> slots;  // handed out, row not yet written
  std::deque<std::size_t> ready;      // resolved, to run
  std::deque<int> waiting;            // ranks that asked for a case while none was ready
  std::size_t next_case = 0, next_row = 0, cached = 0, ran = 0, unresolved = 0;
  double case_time = 0.0;
  Progress progress(total, 0, !o.quiet);
  ReportData report(study);
  std::unique_ptr<ResultsWriter> results;
  const auto finished = [&](std::size_t i, Outcome out) {
    Slot& sl = slots.at(i);
    sl.record.outcome = std::move(out);
    sl.finished = true;
  };
  // Makes and resolves the next case: reused from DIR/cases, failed (it does not resolve), or ready.
  const auto prepare_next = [&]() {
    const std::size_t i = next_case++;
    Slot& sl = slots[i];
    CaseRecord& c = sl.record;
    c.spec = case_at(study, i);
    try {
      c.resolved = resolver->resolve(c.spec);
    } catch (const StudyError& e) {
      // Only a case the probes did not cover (another draw, another combination of axes) gets
      // here: a failed case in results.csv, like a run that fails (docs/study.md, Validation).
      Outcome out;
      out.error = e.what();
      ++unresolved;
      for (const Variation& v : c.spec.variations)  // its row shows the values given (a factor has no nominal value here)
        if (!v.scale) c.resolved.parameters[v.key] = v.value;
      for (char& ch : out.error)
        if (ch == '\n' || ch == '\r') ch = ' ';
      finished(i, std::move(out));
      return;
    }
    const fs::path yaml = dir / "cases" / (c.resolved.hash + ".yaml");
    const fs::path json = dir / "cases" / (c.resolved.hash + ".json");
    std::error_code ec;
    if (fs::exists(json, ec)) {
      if (auto prev = parse_outcome(slurp(json), c.resolved.hash); prev && (prev->ok || !o.retry_failed)) {
        c.cached = true;
        finished(i, std::move(*prev));
        return;
      }
    }
    if (!fs::exists(yaml, ec)) output::write_file_atomically(yaml, c.resolved.yaml);
    ready.push_back(i);
  };
  // Writes the rows of the finished cases at the head of the study order.
  const auto write_rows = [&]() {
    for (auto it = slots.begin(); it != slots.end() && it->first == next_row && it->second.finished; it = slots.erase(it)) {
      const CaseRecord& c = it->second.record;
      results->add(it->first, c);
      report.add(it->first, c);
      if (c.cached) {
        ++cached;
        progress.reused();
      } else {
        progress.step(!c.outcome.ok);
      }
      ++next_row;
    }
  };
  const auto record = [&](std::size_t i, Outcome out) {
    if (out.interrupted) return;  // not an outcome: the case runs again next time
    const Slot& sl = slots.at(i);
    case_time += out.wall_s;
    ++ran;
    output::write_file_atomically(dir / "cases" / (sl.record.resolved.hash + ".json"), outcome_json(sl.record.resolved.hash, out));
    finished(i, std::move(out));
  };
  try {
    results = std::make_unique<ResultsWriter>(study, dir);
    CasePool pool(jobs);
    int released = 0;  // ranks told there is no more work
    while (next_row < total || (t && released < t->size() - 1)) {
      if (interrupt::interrupted()) {
        // Ctrl-C or SIGTERM: the running cases stop at their next poll; what finished is kept.
        while (pool.in_flight() > 0)
          if (auto r = pool.pop(std::chrono::milliseconds(100))) record(r->first, std::move(r->second));
        progress.finish();
        return interrupted_exit(t, ": " + std::to_string(next_row) + " of " + std::to_string(total) +
                                       " cases finished in order (and every case run is kept in " + dir.string() +
                                       "/cases); run the same command to go on");
      }
      // Hand out cases in order, within the window, as long as a thread or a rank can take one.
      const std::size_t want = static_cast<std::size_t>(jobs) + waiting.size() + (t ? 1 : 0);
      while (next_case < total && next_case - next_row < window && ready.size() < want && !interrupt::interrupted())
        prepare_next();
      while (pool.in_flight() < static_cast<std::size_t>(jobs) && !ready.empty()) {
        pool.push(ready.front(), slots.at(ready.front()).record.resolved.yaml);
        ready.pop_front();
      }
      while (t && !waiting.empty() && (!ready.empty() || next_case == total)) {
        const int rank = waiting.front();
        waiting.pop_front();
        if (ready.empty()) {
          t->send(rank, kAssign, "");
          ++released;
        } else {
          const std::size_t i = ready.front();
          ready.pop_front();
          t->send(rank, kAssign, pack(i, slots.at(i).record.resolved.yaml));
        }
      }
      write_rows();
      const bool busy = pool.in_flight() > 0 || t;
      if (busy) {
        if (auto r = pool.pop(std::chrono::milliseconds(t ? 2 : 200))) record(r->first, std::move(r->second));
      }
      while (t) {
        auto m = t->poll();
        if (!m) break;
        if (m->tag == kRequest) {
          waiting.push_back(m->from);
        } else if (m->tag == kResult) {
          auto [i, text] = unpack(m->payload);
          if (!slots.count(i) || slots.at(i).finished)
            throw std::runtime_error("rank " + std::to_string(m->from) + " sent an outcome for no case it was given");
          auto out = parse_outcome(text, "");  // the other ranks do not hash: the index names the case
          if (!out) throw std::runtime_error("rank " + std::to_string(m->from) + " sent a malformed outcome for case " + std::to_string(i));
          record(i, std::move(*out));
        }
      }
      write_rows();
    }
  } catch (const interrupt::Interrupted&) {
    progress.finish();
    return interrupted_exit(t, ": " + std::to_string(next_row) + " of " + std::to_string(total) + " cases finished in order; run the same command to go on");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "\nerror: %s\n", e.what());
    if (t) t->abort(1);
    return 1;
  }
  progress.finish();

  try {
    results->finish();
    std::string plots_md = "Plots skipped (--no-plots).\n\n";
    if (o.plots) {
      const fs::path partial = dir / ".plots.partial";
      std::error_code ec;
      fs::remove_all(partial, ec);
      try {
        plots_md = write_plots(partial, "plots/", report);
        output::replace_folder(partial, dir / "plots");  // never a moment without plots/
      } catch (const interrupt::Interrupted&) {
        fs::remove_all(partial, ec);
        throw;
      } catch (const std::runtime_error& e) {  // a view of the results: results.csv and report.md still go
        fs::remove_all(partial, ec);
        std::fprintf(stderr, "warning: plots not drawn (%s); the results are in %s\n", e.what(), dir.c_str());
        plots_md = "Plots not drawn: " + std::string(e.what()) + "\n\n";
      }
    }
    output::write_file_atomically(dir / "report.md", report_md(report, o.command, plots_md));
    nlohmann::ordered_json timing;
    timing["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    timing["cases"] = total;
    timing["cases_run"] = ran;
    timing["cases_reused"] = cached;
    timing["cases_not_resolved"] = unresolved;  // failed before running: their scenario is invalid
    timing["case_time_sum_s"] = case_time;
    timing["threads_per_rank"] = jobs;
    timing["ranks"] = ranks;
    output::write_file_atomically(dir / "timing.json", timing.dump(2) + "\n");
  } catch (const interrupt::Interrupted&) {
    return interrupted_exit(t, ": every case finished and is kept in " + dir.string() + "/cases; run the same command to write the report");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  // The loader's warnings (an implausible value with its likely unit, a move cut off by
  // duration): once each, with the number of cases that have it, as report.md lists them.
  if (!o.quiet) {
    for (const std::string& w : warning_lines(report)) std::fprintf(stderr, "warning: %s\n", w.c_str());
    if (report.moves_unfinished > 0)
      std::fprintf(stderr, "warning: %zu of %zu cases did not finish their move within duration (move_finished in results.csv)\n",
                   report.moves_unfinished, report.moves);
  }
  if (!o.quiet || report.failed > 0)
    std::fprintf(stderr, "%s: %zu cases (%zu run, %zu reused), %zu failed (see results.csv) -> %s/results.csv, report.md\n",
                 study.name.c_str(), total, ran, cached, report.failed, dir.c_str());
  return 0;
}

int serve(Transport& t, int jobs) {
  const int status = t.broadcast(0);
  if (status != 0) return status;
  if (jobs <= 0) jobs = std::max(1, available_cores() / t.local_size());
  CasePool pool(jobs);
  bool done = false;
  while (!done || pool.in_flight() > 0) {
    if (!done && pool.in_flight() < static_cast<std::size_t>(jobs)) {
      t.send(0, kRequest, "");
      const Message m = t.receive(0);
      if (m.payload.empty()) {
        done = true;
      } else {
        auto [i, text] = unpack(m.payload);
        pool.push(i, std::move(text));
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
