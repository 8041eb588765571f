#include "feeddrive/study/session.hpp"

#include <fcntl.h>
#include <sched.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
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

int run_study(const Options& o, Transport* t) {
  const auto start = std::chrono::steady_clock::now();
  Study study;
  std::vector<CaseRecord> cases;
  fs::path dir;
  std::unique_ptr<FolderLock> lock;
  // Everything that can be wrong with the input, before any case runs: exit 2, and the other
  // ranks are told to stop.
  try {
    study = load_study(o.study);
    if (!o.list) output::check_output_dir(o.out);
    const std::vector<CaseSpec> specs = expand(study);
    Resolver resolver(study);
    cases.reserve(specs.size());
    for (const CaseSpec& c : specs) cases.push_back({c, resolver.resolve(c), {}, false});
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    if (t) t->broadcast(2);
    return 2;
  }
  if (o.list) {
    std::printf("%zu cases\n", cases.size());
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const CaseRecord& c = cases[i];
      std::string params;
      for (const auto& v : c.spec.variations) params += " " + v.key + "=" + c.resolved.parameters.at(v.key);
      std::printf("%zu %s %s %s%s\n", i, c.resolved.hash.substr(0, 16).c_str(), study.controllers[c.spec.controller].name.c_str(),
                  study.families[c.spec.family].name.c_str(), params.c_str());
    }
    if (t) t->broadcast(2);
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

  // Finished cases of an earlier run; the rest is pending, in study order.
  std::deque<std::size_t> pending;
  std::size_t cached = 0;
  try {
    for (std::size_t i = 0; i < cases.size(); ++i) {
      CaseRecord& c = cases[i];
      const fs::path yaml = dir / "cases" / (c.resolved.hash + ".yaml");
      const fs::path json = dir / "cases" / (c.resolved.hash + ".json");
      std::error_code ec;
      if (fs::exists(json, ec)) {
        if (auto prev = parse_outcome(slurp(json), c.resolved.hash); prev && (prev->ok || !o.retry_failed)) {
          c.outcome = *prev;
          c.cached = true;
          ++cached;
          continue;
        }
      }
      if (!fs::exists(yaml, ec)) output::write_file_atomically(yaml, c.resolved.yaml);
      pending.push_back(i);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    if (t) t->abort(1);
    return 1;
  }

  const int jobs = o.jobs > 0 ? o.jobs : std::max(1, available_cores() / (t ? t->local_size() : 1));
  const int ranks = t ? t->size() : 1;
  if (!o.quiet)
    std::fprintf(stderr, "%s: %zu cases (%zu to run, %zu finished earlier) on %d thread%s x %d rank%s -> %s\n",
                 study.name.c_str(), cases.size(), pending.size(), cached, jobs, jobs == 1 ? "" : "s", ranks,
                 ranks == 1 ? "" : "s", dir.c_str());

  Progress progress(cases.size(), cached, !o.quiet);
  double case_time = 0.0;
  std::size_t remaining = pending.size();
  const auto record = [&](std::size_t i, Outcome out) {
    if (out.interrupted) return;  // not an outcome: the case runs again next time
    CaseRecord& c = cases[i];
    c.outcome = std::move(out);
    case_time += c.outcome.wall_s;
    output::write_file_atomically(dir / "cases" / (c.resolved.hash + ".json"), outcome_json(c.resolved.hash, c.outcome));
    progress.step(!c.outcome.ok);
    --remaining;
  };
  try {
    Pool pool(jobs, [&cases](std::size_t i) { return run_case(cases[i].resolved.yaml); });
    int released = 0;  // ranks told there is no more work
    while (remaining > 0 || (t && released < t->size() - 1)) {
      if (interrupt::interrupted()) {
        // Ctrl-C or SIGTERM: the running cases stop at their next poll; what finished is kept.
        while (pool.in_flight() > 0)
          if (auto r = pool.pop(std::chrono::milliseconds(100))) record(r->first, std::move(r->second));
        progress.finish();
        const int sig = interrupt::signal_number();
        std::fprintf(stderr, "interrupted by %s: %zu of %zu cases finished and kept in %s; run the same command to go on\n",
                     interrupt::signal_name(sig).c_str(), cases.size() - remaining, cases.size(), dir.c_str());
        if (t) t->abort(128 + sig);
        return 128 + sig;
      }
      while (pool.in_flight() < static_cast<std::size_t>(jobs) && !pending.empty()) {
        pool.push(pending.front());
        pending.pop_front();
      }
      if (auto r = pool.pop(std::chrono::milliseconds(t ? 2 : 200))) record(r->first, std::move(r->second));
      while (t) {
        auto m = t->poll();
        if (!m) break;
        if (m->tag == kRequest) {
          if (pending.empty()) {
            t->send(m->from, kAssign, "");
            ++released;
          } else {
            const std::size_t i = pending.front();
            pending.pop_front();
            t->send(m->from, kAssign, pack(i, cases[i].resolved.yaml));
          }
        } else if (m->tag == kResult) {
          auto [i, text] = unpack(m->payload);
          if (i >= cases.size()) throw std::runtime_error("rank " + std::to_string(m->from) + " sent an outcome for no case");
          auto out = parse_outcome(text, "");  // the other ranks do not hash: the index names the case
          if (!out) throw std::runtime_error("rank " + std::to_string(m->from) + " sent a malformed outcome for case " + std::to_string(i));
          record(i, std::move(*out));
        }
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "\nerror: %s\n", e.what());
    if (t) t->abort(1);
    return 1;
  }
  progress.finish();

  std::size_t failed = 0;
  for (const CaseRecord& c : cases) failed += c.outcome.ok ? 0 : 1;
  try {
    output::write_file_atomically(dir / "results.csv", results_csv(study, cases));
    std::string plots_md = "Plots skipped (--no-plots).\n\n";
    if (o.plots) {
      const fs::path partial = dir / ".plots.partial";
      std::error_code ec;
      fs::remove_all(partial, ec);
      try {
        plots_md = write_plots(partial, "plots/", study, cases);
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
    output::write_file_atomically(dir / "report.md", report_md(study, cases, o.command, plots_md));
    nlohmann::ordered_json timing;
    timing["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    timing["cases"] = cases.size();
    timing["cases_run"] = cases.size() - cached;
    timing["cases_reused"] = cached;
    timing["case_time_sum_s"] = case_time;
    timing["threads_per_rank"] = jobs;
    timing["ranks"] = ranks;
    output::write_file_atomically(dir / "timing.json", timing.dump(2) + "\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  if (!o.quiet || failed > 0)
    std::fprintf(stderr, "%s: %zu cases, %zu failed (see results.csv) -> %s/results.csv, report.md\n", study.name.c_str(),
                 cases.size(), failed, dir.c_str());
  return 0;
}

int serve(Transport& t, int jobs) {
  const int status = t.broadcast(0);
  if (status != 0) return status;
  if (jobs <= 0) jobs = std::max(1, available_cores() / t.local_size());
  std::map<std::size_t, std::string> yaml;  // the cases this rank holds, filled by the main thread
  std::mutex yaml_mu;
  Pool pool(jobs, [&yaml, &yaml_mu](std::size_t i) {
    std::string text;
    {
      std::lock_guard<std::mutex> lock(yaml_mu);
      text = std::move(yaml.at(i));
      yaml.erase(i);
    }
    return run_case(text);
  });
  bool done = false;
  while (!done || pool.in_flight() > 0) {
    if (!done && pool.in_flight() < static_cast<std::size_t>(jobs)) {
      t.send(0, kRequest, "");
      const Message m = t.receive(0);
      if (m.payload.empty()) {
        done = true;
      } else {
        auto [i, text] = unpack(m.payload);
        {
          std::lock_guard<std::mutex> lock(yaml_mu);
          yaml[i] = std::move(text);
        }
        pool.push(i);
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
