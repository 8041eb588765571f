// feeddrive-study: runs a study (a base scenario plus variations, docs/study.md) on all cores, or
// on all ranks of an MPI job (mpirun, srun), and writes DIR/{results.csv, report.md, plots/}.
//
//   study.yaml --> load_study --> probe cases --> case_at + resolve, one at a time --> cases in parallel
//              --> results.csv (streamed in study order), report.md
//
// Exit codes: 0 done (failed cases are reported in results.csv), 2 bad input (study, options,
// output folder), 1 a failure of the machine.
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include <cstdio>
#include <optional>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/study/session.hpp"
#include "feeddrive/study/spec.hpp"
#include "feeddrive/study/transport.hpp"
#include "feeddrive/tool/main.hpp"
#include "progress.hpp"

namespace {

// What run_study tells, printed: the cases of --list on stdout, the progress on stderr, the rest
// in the one logging style (spdlog, tool::setup_logging).
class Printer final : public feeddrive::study::Reporter {
 public:
  explicit Printer(bool quiet) : quiet_(quiet) {}
  void listed(const std::string& line) override { std::printf("%s\n", line.c_str()); }
  void started(const std::string& line) override { spdlog::info("{}", line); }
  void progress_start(std::size_t total) override { progress_.emplace(total, 0, !quiet_); }
  void progress_step(bool reused, bool failed) override {
    if (reused) progress_->reused();
    else progress_->step(failed);
  }
  void progress_end() override {
    if (progress_) progress_->finish();
  }
  void warning(const std::string& line) override { spdlog::warn("{}", line); }

 private:
  bool quiet_;
  std::optional<feeddrive::study::Progress> progress_;
};

}  // namespace

int main(int argc, char** argv) {
  std::string command = "feeddrive-study";
  for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
  std::unique_ptr<feeddrive::study::Transport> transport;
  try {
    transport = feeddrive::study::connect(argc, argv);
  } catch (...) {
    return feeddrive::tool::report(std::current_exception());
  }
  CLI::App app{
      "feeddrive-study: runs a study of many scenarios (grid, Monte Carlo, controllers) on all cores or MPI ranks"};
  feeddrive::study::Options o;
  bool no_plots = false;
  app.add_option("study", o.study, "study YAML file (docs/study.md), or with --sweep a scenario file")->required();
  app.add_option("--set", o.sets, "KEY=VALUE: set a scenario key in every case (after the study's own set); repeatable")
      ->type_name("KEY=VALUE");
  app.add_option(
         "--sweep", o.sweeps,
         "KEY=V1,V2,... | KEY=START:STOP:N | KEY=log:START:STOP:N: vary a key of the scenario file given instead "
         "of a study (repeat for a grid)")
      ->type_name("SWEEP");
  app.add_option("--out,-o", o.out, "output folder; a rerun into it skips the finished cases (not needed with --list)");
  app.add_option("-j,--jobs", o.jobs,
                 "worker threads (default: every core; per MPI rank: the host's cores / its ranks)")
      ->check(feeddrive::tool::within(1, 4096, true));
  app.add_flag("--no-plots", no_plots, "skip the plots");
  app.add_flag("--retry-failed", o.retry_failed, "run again the cases that failed in an earlier run into DIR");
  app.add_flag("--list", o.list, "print the resolved cases and exit");
  app.add_flag("--quiet,-q", o.quiet, "no progress, print only errors");
  // Not tool::run: every rank parses the same arguments (tool::parse), and only rank 0 (or the
  // process alone) speaks; then the one mapping of every tool (tool::report).
  const bool speaks = !transport || transport->rank() == 0;
  if (const std::optional<int> rc = feeddrive::tool::parse(app, argc, argv, speaks)) return *rc;
  if (o.out.empty() && !o.list) {
    if (!speaks) return 2;
    return feeddrive::tool::report(
        std::make_exception_ptr(feeddrive::BadInput("--out is required (except with --list)")));
  }
  o.plots = !no_plots;
  o.command = command;
  feeddrive::tool::setup_logging("feeddrive-study", o.quiet);
  // Ctrl-C / SIGTERM: the running cases stop, the finished ones stay in DIR/cases.
  feeddrive::tool::install_interrupt_handlers();
  o.stop = feeddrive::tool::stop_token();
  try {
    if (!speaks) return feeddrive::study::serve(*transport, o.jobs, o.stop);
    Printer printer(o.quiet);
    const feeddrive::study::StudyResult r = feeddrive::study::run_study(o, transport.get(), printer);
    if (r.dir.empty()) return 0;  // --list
    // The loader's warnings (an implausible value with its likely unit, a move cut off by
    // duration): once each, with the number of cases that have it, as report.md lists them.
    for (const std::string& w : r.warnings) spdlog::warn("{}", w);
    if (r.moves_unfinished > 0)
      spdlog::warn("{} of {} cases did not finish their move within duration (move_finished in results.csv)",
                   r.moves_unfinished, r.moves);
    const std::string line = r.name + ": " + std::to_string(r.total) + " cases (" + std::to_string(r.ran) + " run, " +
                             std::to_string(r.reused) + " reused), " + std::to_string(r.failed) +
                             " failed (see results.csv) -> " + r.dir + "/results.csv, report.md";
    if (r.failed > 0) spdlog::warn("{}", line);
    else spdlog::info("{}", line);
    return 0;
  } catch (...) {
    return feeddrive::tool::report(std::current_exception());
  }
}
