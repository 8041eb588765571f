// feeddrive-study: runs a study (a base scenario plus variations, docs/study.md) on all cores, or
// on all ranks of an MPI job (mpirun, srun), and writes DIR/{results.csv, report.md, plots/}.
//
//   study.yaml --> load_study --> probe cases --> case_at + resolve, one at a time --> cases in parallel
//              --> results.csv (streamed in study order), report.md
//
// Exit codes: 0 done (failed cases are reported in results.csv), 2 bad input (study, options,
// output folder), 1 a failure of the machine.
#include <CLI/CLI.hpp>

#include <cstdio>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/study/session.hpp"
#include "feeddrive/study/spec.hpp"
#include "feeddrive/study/transport.hpp"
#include "feeddrive/tool/main.hpp"

int main(int argc, char** argv) {
  std::string command = "feeddrive-study";
  for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
  std::unique_ptr<feeddrive::study::Transport> transport;
  try {
    transport = feeddrive::study::connect(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  CLI::App app{"feeddrive-study: runs a study of many scenarios (grid, Monte Carlo, controllers) on all cores or MPI ranks"};
  feeddrive::study::Options o;
  bool no_plots = false;
  app.add_option("study", o.study, "study YAML file (docs/study.md), or with --sweep a scenario file")->required();
  app.add_option("--set", o.sets, "KEY=VALUE: set a scenario key in every case (after the study's own set); repeatable")
      ->type_name("KEY=VALUE");
  app.add_option("--sweep", o.sweeps,
                 "KEY=V1,V2,... | KEY=START:STOP:N | KEY=log:START:STOP:N: vary a key of the scenario file given instead "
                 "of a study (repeat for a grid)")
      ->type_name("SWEEP");
  app.add_option("--out,-o", o.out, "output folder; a rerun into it skips the finished cases (not needed with --list)");
  app.add_option("-j,--jobs", o.jobs, "worker threads (default: every core; per MPI rank: the host's cores / its ranks)")
      ->check(CLI::Range(1, 4096));
  app.add_flag("--no-plots", no_plots, "skip the plots");
  app.add_flag("--retry-failed", o.retry_failed, "run again the cases that failed in an earlier run into DIR");
  app.add_flag("--list", o.list, "print the resolved cases and exit");
  app.add_flag("--quiet,-q", o.quiet, "no progress, print only errors");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Every rank parses the same arguments: only rank 0 (or the process alone) speaks.
    const int rc = (!transport || transport->rank() == 0) ? app.exit(e) : (e.get_exit_code() == 0 ? 0 : 2);
    return rc == 0 ? 0 : 2;
  }
  if (o.out.empty() && !o.list) {
    if (!transport || transport->rank() == 0) std::fprintf(stderr, "error: --out is required (except with --list)\n");
    return 2;
  }
  o.plots = !no_plots;
  // Ctrl-C / SIGTERM: the running cases stop, the finished ones stay in DIR/cases.
  feeddrive::tool::install_interrupt_handlers();
  o.command = command;
  if (transport && transport->rank() != 0) return feeddrive::study::serve(*transport, o.jobs);
  return feeddrive::study::run_study(o, transport.get());
}
