#include "feeddrive/service/launch.hpp"

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>

#include <stdexcept>
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/process_status_t.hpp"
#include "feeddrive/service/bus.hpp"
#include "feeddrive/service/integrity.hpp"
#include "feeddrive/service/loggers.hpp"

#include "feeddrive/common/interrupt.hpp"

namespace feeddrive::service {
namespace {

std::string fmt_double(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::vector<std::string> common_args(const NodeOptions& opt) {
  std::vector<std::string> a = {"--lcm-url",          opt.lcm_url,
                                "--prefix",           opt.prefix,
                                "--start-timeout",    fmt_double(opt.start_timeout_s),
                                "--step-timeout",     fmt_double(opt.step_timeout_s),
                                "--resend-interval",  fmt_double(opt.resend_interval_s),
                                "--monitor-window",   std::to_string(opt.monitor_window),
                                "--linger",           fmt_double(opt.linger_s),
                                "--max-bad-commands", std::to_string(opt.max_bad_commands),
                                "--spin-us",          std::to_string(opt.realtime_spin_us)};
  if (opt.realtime) a.push_back("--realtime");
  if (opt.max_rate > 0) a.insert(a.end(), {"--max-rate", fmt_double(opt.max_rate)});
  if (opt.run_id != 0) a.insert(a.end(), {"--run-id", std::to_string(opt.run_id)});
  if (!opt.scenario_hash.empty()) a.insert(a.end(), {"--scenario-hash", opt.scenario_hash});
  if (!opt.key_file.empty()) a.insert(a.end(), {"--key", opt.key_file});
  if (!opt.key_file.empty() && opt.run_nonce != 0) a.insert(a.end(), {"--run-nonce", std::to_string(opt.run_nonce)});
  if (opt.on_conflict != ConflictPolicy::kFail)
    a.insert(a.end(), {"--on-conflict", fields::enum_name(opt.on_conflict)});
  for (const std::string& set : opt.sets) a.insert(a.end(), {"--set", set});
  return a;
}

// The children's refusals (interrupt::kRefusalFdEnv): a pipe whose write end they inherit. Read
// when they have all exited; each different line once, in order.
class RefusalPipe {
 public:
  RefusalPipe() {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC | O_NONBLOCK) != 0) return;  // none: the children print to stderr
    read_ = fds[0];
    // The write end is inherited by the children (no close-on-exec there): dup'ed without it.
    write_ = ::fcntl(fds[1], F_DUPFD, 3);
    ::close(fds[1]);
  }
  ~RefusalPipe() {
    if (read_ >= 0) ::close(read_);
    if (write_ >= 0) ::close(write_);
  }
  RefusalPipe(const RefusalPipe&) = delete;
  RefusalPipe& operator=(const RefusalPipe&) = delete;
  int write_fd() const { return write_; }
  std::vector<std::string> lines() {
    std::string text;
    char buf[4096];
    for (ssize_t n; read_ >= 0 && (n = ::read(read_, buf, sizeof buf)) > 0;)
      text.append(buf, static_cast<std::size_t>(n));
    std::vector<std::string> out;
    std::size_t start = 0;
    while (start < text.size()) {
      const std::size_t end = std::min(text.find('\n', start), text.size());
      const std::string line = text.substr(start, end - start);
      if (!line.empty() && std::find(out.begin(), out.end(), line) == out.end()) out.push_back(line);
      start = end + 1;
    }
    return out;
  }

 private:
  int read_{-1}, write_{-1};
};

pid_t spawn(const std::string& exe, const std::vector<std::string>& args, int niceness, const std::vector<int>& cpus,
            int refusal_fd) {
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(exe.c_str()));
  for (const auto& s : args) argv.push_back(const_cast<char*>(s.c_str()));
  argv.push_back(nullptr);
  // SIGINT and SIGTERM stay blocked from before the fork until the new program has installed its
  // handlers (tool::install_interrupt_handlers unblocks them): a Ctrl-C that reaches the child between
  // fork and exec stays pending instead of being lost with the launcher's handler at exec (the
  // child then ran on to its 10 s start timeout).
  const pid_t launcher = ::getpid();
  // What the child may say, prepared before fork: between fork and exec it makes only system
  // calls (write(2), no stdio: another thread of the launcher may hold stdio's lock), and it has
  // no caller to return an error to. Its exit code 127 tells the launcher that exec failed.
  const std::string nice_failed = "warning: nice(" + std::to_string(niceness) + ") failed\n";
  const std::string affinity_failed = "warning: sched_setaffinity failed\n";
  const std::string exec_failed = "error: cannot execute " + exe + "\n";
  const std::string refusal_fd_text = std::to_string(refusal_fd);
  const auto say = [](const std::string& line) {
    [[maybe_unused]] const auto n = ::write(2, line.data(), line.size());
  };
  sigset_t stop, old;
  sigemptyset(&stop);
  sigaddset(&stop, SIGINT);
  sigaddset(&stop, SIGTERM);
  ::pthread_sigmask(SIG_BLOCK, &stop, &old);
  const pid_t pid = ::fork();
  if (pid != 0) ::pthread_sigmask(SIG_SETMASK, &old, nullptr);
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    // Children die with their launcher, even a SIGKILLed one (which cannot forward anything):
    // the kernel sends them SIGTERM (their handlers stop the run and keep what is recorded). If
    // the launcher died before this line, the parent is no longer it: stop at once.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != launcher) ::_exit(143);
    if (niceness != 0 && ::nice(niceness) == -1) say(nice_failed);
    if (!cpus.empty()) {
      cpu_set_t set;
      CPU_ZERO(&set);
      for (int c : cpus) CPU_SET(c, &set);
      if (::sched_setaffinity(0, sizeof set, &set) != 0) say(affinity_failed);
    }
    ::setenv(interrupt::kQuietEnv, "1", 1);  // an interrupt is reported once, by the launcher
    if (refusal_fd >= 0) ::setenv(interrupt::kRefusalFdEnv, refusal_fd_text.c_str(), 1);  // and a refusal
    ::execv(exe.c_str(), argv.data());
    say(exec_failed);
    ::_exit(127);
  }
  return pid;
}

}  // namespace

std::string executable_dir() { return std::filesystem::read_symlink("/proc/self/exe").parent_path().string(); }

std::vector<int> parse_cpu_list(const std::string& text, const std::string& option) {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (::sched_getaffinity(0, sizeof allowed, &allowed) != 0) throw std::runtime_error("sched_getaffinity failed");
  std::vector<int> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, end - start);
    char* stop = nullptr;
    const long c = std::strtol(item.c_str(), &stop, 10);
    if (item.empty() || *stop != '\0' || c < 0 || c >= CPU_SETSIZE || !CPU_ISSET(static_cast<int>(c), &allowed))
      throw std::invalid_argument(option + " " + text + ": '" + item + "' is not a CPU this process may use");
    out.push_back(static_cast<int>(c));
    start = end + 1;
  }
  return out;
}

void check_group_free(const NodeOptions& opt, double listen_s) {
  Bus probe(opt.lcm_url);
  const Channels ch(opt.prefix);
  std::string holder;
  // Any run's messages: the probe has not joined one (and has no key: any run counts).
  probe.subscribe<process_status_t>(
      ch.status,
      [&](const process_status_t& m, std::int64_t) {
        if (holder.empty() && m.role == "plant")
          holder =
              "run id " + std::to_string(m.run_id) + ", its plant " + m.state + " at step " + std::to_string(m.seq);
      },
      Admit::kAnyRun);
  probe.subscribe<drive_state_t>(
      ch.state,
      [&](const drive_state_t& m, std::int64_t) {
        if (holder.empty())
          holder = "run id " + std::to_string(m.run_id) + ", its plant at step " + std::to_string(m.seq);
      },
      Admit::kAnyRun);
  const std::int64_t end = mono_us() + us(listen_s);
  while (holder.empty() && mono_us() < end)
    probe.poll(std::chrono::microseconds(std::max<std::int64_t>(end - mono_us(), 1)));
  if (holder.empty()) return;
  const std::optional<UdpmAddress> a = parse_udpm_url(opt.lcm_url);
  const std::string other_port =
      a ? "udpm://" + a->group + ":" + std::to_string(a->port + 1) + "?ttl=0" : "another URL";
  throw std::invalid_argument("another run holds " + opt.prefix + "_* on " + opt.lcm_url + " (" + holder +
                              "): give this one another --prefix (e.g. --prefix " + opt.prefix +
                              "2) or --lcm-url (e.g. '" + other_port + "'), and the same to its external processes");
}

namespace {

// Each --external ROLE must be one that can run outside (the monitor cannot).
void check_external(const LaunchOptions& lo) {
  for (const auto& r : lo.external)
    if (r != "controller" && r != "plant" && r != "trajectory")
      throw std::invalid_argument("--external " + r + ": expected one of controller, plant, trajectory");
}

// The options every process gets: the run id (and, with a key, the nonce) drawn once the group
// is known to be free, and the pace a stock lcm-logger on the bus needs.
NodeOptions run_options(const LaunchOptions& lo, const NodeOptions& given) {
  NodeOptions opt = given;
  if (!lo.external.count("plant")) {
    // The group must be free: another run's plant on it means a second run (point of
    // docs/security.md, "Concurrent runs"). An external plant is expected there, so no check.
    if (lo.busy_check_s > 0) check_group_free(opt, lo.busy_check_s);
    if (opt.run_id == 0) opt.run_id = draw_run_id();
    // With a key, a fresh nonce binds the run id on the wire to this run (docs/security.md).
    if (!opt.key_file.empty() && opt.run_nonce == 0) opt.run_nonce = draw_run_id();
    spdlog::info("run id {}{}", opt.run_id,
                 opt.key_file.empty() ? "" : " (messages authenticated with " + opt.key_file + ")");
  } else if (opt.run_id == 0) {
    spdlog::info("the plant is external: every process joins the run id of its heartbeat (or give --run-id)");
  }
  // A stock lcm-logger started before the run records it only if the run is paced (loggers.hpp).
  if (lo.auto_pace && !opt.realtime && !lo.external.count("plant")) {
    const std::vector<StockLogger> loggers = stock_loggers_on(opt.lcm_url);
    if (!loggers.empty()) {
      opt.max_rate = stock_logger_pace(loggers);
      spdlog::info(
          "{} on the bus: the run is paced to {:g} steps/s, which it records without loss{} (--max-rate N to "
          "choose, --max-rate 0 for none; docs/lcm-contract.md)",
          describe(loggers), opt.max_rate,
          opt.max_rate < kStockLoggerSteps ? "; at real-time priority (chrt -f 20) it keeps up with 1000" : "");
    }
  }
  return opt;
}

// The line that tells how to start an external role: its options and this run's settings.
void describe_external(const std::string& role, const NodeOptions& opt) {
  spdlog::info(
      "{} is external: start it yourself with --lcm-url '{}' --prefix {}{}{}{} --scenario-hash {} (this "
      "scenario's; a participant with another scenario is refused); this run is {} (--realtime), "
      "--start-timeout {} s, --step-timeout {} s, --resend-interval {} s, --monitor-window {}, all in run_info_t "
      "(docs/external-{}.md)",
      role, opt.lcm_url, opt.prefix, opt.run_id != 0 ? " --run-id " + std::to_string(opt.run_id) : "",
      opt.key_file.empty() ? "" : " --key " + opt.key_file,
      opt.run_nonce != 0 && !opt.key_file.empty() ? " --run-nonce " + std::to_string(opt.run_nonce) : "",
      opt.scenario_hash, opt.realtime ? "real time" : "lockstep", seconds_text(opt.start_timeout_s),
      seconds_text(opt.step_timeout_s), seconds_text(opt.resend_interval_s), opt.monitor_window,
      role == "plant" ? "plant" : "controllers");
}

// The command line of one role's process: the scenario, the options every process gets, and the
// monitor's output options.
std::vector<std::string> role_args(const std::string& role, const LaunchOptions& lo, const NodeOptions& opt) {
  std::vector<std::string> args = {lo.scenario};
  const auto common = common_args(opt);
  args.insert(args.end(), common.begin(), common.end());
  if (role != "monitor" || opt.quiet) args.push_back("--quiet");
  if (role == "monitor") {
    args.insert(args.end(), {"--out", lo.out_dir});
    if (!lo.plots) args.push_back("--no-plots");
    if (!lo.lcm_log.empty()) args.insert(args.end(), {"--lcm-log", lo.lcm_log});
  }
  return args;
}

// Starts the roles that are not external, monitor first; returns pid -> role.
std::map<pid_t, std::string> start_roles(const LaunchOptions& lo, const NodeOptions& opt, int refusal_fd) {
  const std::string bin = lo.bin_dir.empty() ? executable_dir() : lo.bin_dir;
  std::map<pid_t, std::string> running;
  for (const std::string role : {"monitor", "plant", "trajectory", "controller"}) {
    if (opt.stop.stop_requested()) break;  // Ctrl-C while starting: start no more (the wait forwards it)
    if (lo.external.count(role)) {
      describe_external(role, opt);
      continue;
    }
    const std::string exe = bin + "/feeddrive-" + role;
    if (::access(exe.c_str(), X_OK) != 0) throw std::runtime_error("cannot find " + exe);
    // The monitor and the trajectory are off the step's critical path (plant -> controller ->
    // plant); how much they yield to it depends on the mode (launch.hpp).
    const bool off_path = role == "monitor" || role == "trajectory";
    const int niceness = off_path ? (opt.realtime ? lo.realtime_off_path_niceness : lo.off_path_niceness) : 0;
    running[spawn(exe, role_args(role, lo, opt), niceness,
                  off_path && !lo.off_path_cpus.empty() ? lo.off_path_cpus : lo.cpus, refusal_fd)] = role;
  }
  return running;
}

// What the wait for the children has seen so far.
struct Wait {
  bool refused{false};  // a process exited 2 (bad input, e.g. a record that cannot fit the disk)
  int forwarded{0};     // the signal forwarded to the children
  std::int64_t first_failure_us{-1};
  double grace_s{0.0};
  bool terminated{false};
};

// A child exited with `status`: a killed monitor's record is rescued, a failure noted (a refusal
// stops the others at once; a failed monitor shortens the grace period).
void child_exited(pid_t pid, int status, const std::string& role, const LaunchOptions& lo,
                  const std::map<pid_t, std::string>& running, Wait& w, LaunchResult& result) {
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  if (role == "monitor" && WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) {
    // A killed monitor could not put its record in place: the launcher does, beside --out.
    try {
      result.partial_record = output::rescue_staging(lo.out_dir, pid).string();
    } catch (const std::exception& e) {
      spdlog::error("monitor killed: {}", e.what());
    }
  }
  if (code == 0) return;
  if (code == 2 && !w.refused) {
    // Bad input: nothing to run. The others are stopped at once, quietly (they would only
    // fail for want of this one); the refusal is the launcher's one line.
    w.refused = true;
    for (const auto& [p, other] : running) ::kill(p, SIGTERM);
    w.terminated = true;
  }
  result.failed.push_back(role + " (exit " + std::to_string(code) + ")");
  if (w.first_failure_us < 0) w.first_failure_us = mono_us();
  // The monitor is the run's record and its judge (it names what the bus drops: an older
  // contract, an unsigned participant): without it the run is over. The others hear its
  // failure within 0.1 s; one that never joined a run (it waited for an external plant the
  // monitor refused) cannot, so it gets 1 s, not the whole grace period.
  if (role == "monitor") w.grace_s = std::min(w.grace_s, 1.0);
}

// Waits until every child has exited: forwards Ctrl-C / SIGTERM to them once, and terminates
// stragglers a grace period after the first failure. Returns whether a child refused (exit 2).
bool wait_for_children(std::map<pid_t, std::string>& running, const LaunchOptions& lo, const interrupt::StopToken& stop,
                       LaunchResult& result) {
  Wait w;
  w.grace_s = lo.grace_s;
  while (!running.empty()) {
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, WNOHANG);
    if (pid > 0) {
      const std::string role = running[pid];
      running.erase(pid);
      child_exited(pid, status, role, lo, running, w, result);
      continue;
    }
    const int sig = stop.signal();
    if (sig != 0 && w.forwarded != sig) {
      w.forwarded = sig;
      for (const auto& [p, role] : running) ::kill(p, sig);
    }
    // One failed: the others notice (status or timeout); terminate stragglers after a grace period.
    if (w.first_failure_us >= 0 && !w.terminated && mono_us() - w.first_failure_us > us(w.grace_s)) {
      w.terminated = true;
      for (const auto& [p, role] : running) {
        spdlog::error("{} still running {} s after a failure: terminating it", role, seconds_text(w.grace_s));
        ::kill(p, SIGTERM);
      }
    }
    ::usleep(20000);
  }
  return w.refused;
}

}  // namespace

LaunchResult launch(const LaunchOptions& lo, const NodeOptions& given) {
  check_external(lo);
  if (!given.key_file.empty()) read_key_file(given.key_file);  // a bad key fails here, before any process
  const NodeOptions opt = run_options(lo, given);
  RefusalPipe refusal_pipe;
  std::map<pid_t, std::string> running = start_roles(lo, opt, refusal_pipe.write_fd());
  LaunchResult result;
  const bool refused = wait_for_children(running, lo, given.stop, result);
  result.refusals = refusal_pipe.lines();
  // Interrupted: every child has stopped (the monitor kept what it had recorded); one line, 130.
  given.stop.check();
  result.exit_code = result.failed.empty() ? 0 : refused ? 2 : 1;
  return result;
}

}  // namespace feeddrive::service
