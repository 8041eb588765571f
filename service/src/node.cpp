#include "feeddrive/service/node.hpp"
#include "feeddrive/wire.hpp"

#include <sched.h>
#include <spdlog/spdlog.h>
#include <sys/mman.h>
#include <sys/prctl.h>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <ctime>
#include <stdexcept>

#include <cstdio>
#include <cstdlib>
#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/run_info_t.hpp"
#include "feeddrive/service/contract.hpp"

namespace feeddrive::service {
std::string enter_realtime(int priority, bool lock_memory) {
  ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  const bool locked = lock_memory && ::mlockall(MCL_CURRENT | MCL_FUTURE) == 0;
  const std::string lock = !lock_memory ? "memory not locked (not asked)"
                           : locked     ? "memory locked"
                                        : std::string("memory not locked (mlockall: ") + std::strerror(errno) + ")";
  const std::string idle = hold_cpu_latency_zero();
  sched_param sp{};
  sp.sched_priority = priority;
  if (::sched_setscheduler(0, SCHED_FIFO, &sp) == 0)
    return "SCHED_FIFO " + std::to_string(priority) + ", " + lock + ", " + idle;
  return std::string("normal scheduling (SCHED_FIFO not permitted: ") + std::strerror(errno) +
         "; needs root, CAP_SYS_NICE or an rtprio limit; expect missed deadlines at high rates), " + lock + ", " + idle;
}

void Node::enter_realtime_if_asked(int priority, bool lock_memory) {
  if (!opt_.realtime || !opt_.realtime_scheduling) return;
  const std::string rt = enter_realtime(priority, lock_memory);
  if (rt.rfind("SCHED_FIFO", 0) == 0) spdlog::info("{}: real time: {}", role_, rt);
  else spdlog::warn("{}: real time: {}", role_, rt);
}

void leave_realtime() {
  sched_param sp{};
  sp.sched_priority = 0;
  ::sched_setscheduler(0, SCHED_OTHER, &sp);  // fails only if never granted: nothing to undo
}

std::string hold_cpu_latency_zero() {
  // One request per process, held to its exit (the kernel drops it when the descriptor closes).
  static int fd = -1;
  if (fd >= 0) return "CPU wake-up latency held at 0 us";
  if (const char* e = std::getenv("FEEDDRIVE_CPU_LATENCY_HOLD"); e != nullptr && std::string(e) == "0")
    return "CPU wake-up latency not held (FEEDDRIVE_CPU_LATENCY_HOLD=0)";
  const int f = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
  if (f < 0)
    return std::string("CPU wake-up latency not held (/dev/cpu_dma_latency: ") + std::strerror(errno) +
           "; idle CPUs may sleep deeply and wake late)";
  const std::int32_t zero = 0;
  if (::write(f, &zero, sizeof zero) != static_cast<ssize_t>(sizeof zero)) {
    const std::string why = std::strerror(errno);
    ::close(f);
    return "CPU wake-up latency not held (/dev/cpu_dma_latency: " + why + ")";
  }
  fd = f;
  return "CPU wake-up latency held at 0 us";
}

void sleep_until(std::int64_t target_us, std::int64_t spin_us, const interrupt::StopToken& stop) {
  const std::int64_t wake = target_us - spin_us;
  if (mono_us() < wake) {
    timespec ts{static_cast<time_t>(wake / 1000000), static_cast<long>((wake % 1000000) * 1000)};
    while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR && !stop.stop_requested()) {}
  }
  while (mono_us() < target_us) {}
}

std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", s);
  return buf;
}

Node::Node(std::string role, const NodeOptions& opt, Receive receive, lcm_t* shared_lcm)
    : role_(std::move(role)), opt_(opt), bus_(opt.lcm_url, receive, shared_lcm), ch_(opt.prefix) {
  set_run_identity();
  // Under feeddrive-launch the monitor names what the bus drops (one line per event); the others count.
  if (std::getenv(interrupt::kQuietEnv) != nullptr && role_ != "monitor") bus_.set_reports(false);
  bus_.subscribe<process_status_t>(
      ch_.status, [this](const process_status_t& m, std::int64_t recv_us) { on_status(m, recv_us); }, Admit::kAnyRun);
  // One run, one scenario: a participant started by hand (an external controller, a drive
  // adapter's companion) with another scenario file than the run's is refused with exit 2 as
  // soon as the monitor's run_info_t names the run's scenario hash (docs/lcm-contract.md).
  if (role_ == "plant" || role_ == "controller" || role_ == "trajectory")
    bus_.subscribe<run_info_t>(ch_.info, [this](const run_info_t& m, std::int64_t) { on_run_info(m); });
  bus_.subscribe<resend_request_t>(ch_.resend, [this](const resend_request_t& m, std::int64_t) {
    if (on_resend_request) on_resend_request(m);
  });
}

void Node::set_run_identity() {
  if (!opt_.key_file.empty()) bus_.set_auth(read_key_file(opt_.key_file));
  const bool keyed = !opt_.key_file.empty();
  if (keyed && opt_.run_id != 0 && opt_.run_nonce != 0) {
    // The launcher gave the run's nonce: the run id on the wire is known from the start.
    run_nonce_ = opt_.run_nonce;
    bus_.set_run_id(keyed_run_id(opt_.run_id, run_nonce_));
  } else if (keyed && role_ == "plant") {
    // A fresh nonce binds this run's identity: a replay of an earlier run with the same
    // --run-id carries another run id (docs/security.md, "Replays across runs").
    run_nonce_ = opt_.run_nonce != 0 ? opt_.run_nonce : draw_run_id();
    bus_.set_run_id(keyed_run_id(opt_.run_id != 0 ? opt_.run_id : draw_run_id(), run_nonce_));
  } else if (opt_.run_id != 0 && !keyed) {
    bus_.set_run_id(opt_.run_id);
  }
}

void Node::on_status(const process_status_t& m, std::int64_t recv_us) {
  if (const std::string src = bus_.current_source(); !src.empty())
    if (status_sources_.size() < 64 || status_sources_.count(src)) status_sources_[src] = {m.run_id, m.role};
  if (!bus_.run_known() && !join_run(m)) return;
  if (m.run_id != bus_.run_id()) {
    bus_.count_foreign(ch_.status, m.run_id, m.role);
    return;
  }
  if (m.role == role_) return;
  if (goes_back(m)) return;
  if (m.role == kAttachedMonitorRole && m.acked_seq != attached_acked_) {
    attached_acked_ = m.acked_seq;
    attached_progress_us_ = recv_us;
  }
  peers_[m.role] = m;
  peer_seen_us_[m.role] = recv_us;
  if (on_peer_status) on_peer_status(m);
}

bool Node::join_run(const process_status_t& m) {
  const bool keyed = !opt_.key_file.empty();
  // Join the run of the first plant whose heartbeat is fresh (its wall clock within 5 s
  // of ours): a log replayed by lcm-logplayer carries the old times and is not joined.
  // Under --key the heartbeat is signed (checked before decode) and must carry the run's
  // nonce, its run id bound to our --run-id by it.
  if (m.role != "plant" || std::llabs(m.utime - wall_utime()) > 5000000) return false;
  if (keyed && m.run_nonce == 0) {
    if (!warned_no_nonce_)
      spdlog::error(
          "{}: the plant's heartbeat carries no run nonce under --key: a plant older than the "
          "contract's version 3 (docs/lcm-contract.md); update it to draw one (docs/security.md)",
          role_);
    warned_no_nonce_ = true;
    return false;
  }
  if (keyed && opt_.run_id != 0 && keyed_run_id(opt_.run_id, m.run_nonce) != m.run_id) {
    bus_.count_foreign(ch_.status, m.run_id);
    return false;
  }
  bus_.set_run_id(m.run_id);
  run_nonce_ = m.run_nonce;
  spdlog::info("{}: joined run {} (taken from the plant's heartbeat{})", role_, m.run_id,
               keyed ? ", bound to its nonce" : "");
  return true;
}

bool Node::goes_back(const process_status_t& m) {
  const bool keyed = !opt_.key_file.empty();
  // A run role's state only moves forward (starting, running, then done or failed): a
  // "running" after its own "done" is a forged or replayed heartbeat, not the process. It
  // is a conflict, and the state it claims is ignored, so no heartbeat can hold a run
  // open (docs/security.md, "Heartbeats").
  // Likewise, at the plant (whose flow control reads it), the monitor's acknowledgement only
  // grows: a heartbeat that takes acked_seq back would stall the plant (a forged one held a
  // run for as long as it was sent). And it cannot pass the plant's own step + 2 (the monitor
  // cannot have recorded a state the plant has not sent), so a forged "acked_seq 10^9"
  // neither raises the bar that real heartbeats must clear nor releases the flow control.
  // All are ignored and counted as conflicts.
  const bool a_monitor = role_ == "plant" && (m.role == "monitor" || m.role == kAttachedMonitorRole);
  const bool implausible = a_monitor && m.acked_seq > seq_ + 2;
  const auto it = peers_.find(m.role);
  const bool tracked = it != peers_.end() && (is_run_role(m.role) || m.role == kAttachedMonitorRole);
  const auto rank = [](const std::string& s) { return s == "starting" ? 0 : s == "running" ? 1 : 2; };
  // With --key, a run role's own step only grows within a state too: a signed "running"
  // heartbeat at an earlier step is a replay (the trajectory paces itself by the plant's
  // step, so a replayed one held the references back for seconds). Signed heartbeats
  // cannot claim a future step, so the rule cannot be poisoned; without a key anyone can
  // forge any step (docs/security.md: detected, not prevented), and the newest one wins.
  const bool seq_back = keyed && tracked && m.state == it->second.state && m.seq < it->second.seq;
  if (!implausible && !seq_back &&
      !(tracked && (rank(m.state) < rank(it->second.state) || (a_monitor && m.acked_seq < it->second.acked_seq))))
    return false;
  const std::string was = tracked ? it->second.state : std::string("-");
  const std::int64_t was_acked = tracked ? it->second.acked_seq : -1;
  ++conflicts;
  const std::int64_t now = mono_us();
  if (now - last_conflict_log_us_ > 1000000) {
    last_conflict_log_us_ = now;
    if (implausible)
      spdlog::warn(
          "{}: conflict on {}: a heartbeat of the {} acknowledges step {}, beyond this {}'s step {}; "
          "forged or replayed; ignored, {} conflicts so far",
          role_, ch_.status, m.role, m.acked_seq, role_, seq_, conflicts);
    else
      spdlog::warn(
          "{}: conflict on {}: a heartbeat of the {} goes back ('{}' at step {} after its own '{}' at "
          "step {}, acknowledged step {} after {}; forged or replayed; ignored, {} conflicts so far)",
          role_, ch_.status, m.role, m.state, m.seq, was, tracked ? it->second.seq : -1, m.acked_seq, was_acked,
          conflicts);
  }
  if (!implausible && on_peer_status_back) on_peer_status_back(m);
  return true;
}

void Node::on_run_info(const run_info_t& m) {
  if (opt_.scenario_hash.empty() || m.scenario_hash.empty() || m.scenario_hash == opt_.scenario_hash ||
      !scenario_mismatch_.empty())
    return;
  scenario_mismatch_ = "this " + role_ + "'s scenario (sha256 " + opt_.scenario_hash.substr(0, 12) +
                       "...) is not the run's (" + m.scenario + ", sha256 " + m.scenario_hash.substr(0, 12) +
                       "... in run_info_t): start it with the run's scenario file; one run, one scenario";
}

Node::~Node() {
  if (const std::int64_t n = bus_.send_errors(); n > 0)
    spdlog::warn("{}: {} LCM message{} could not be sent (publish failed); see the warnings above", role_, n,
                 n == 1 ? "" : "s");
}

process_status_t Node::status_message(const std::string& state, const std::string& message) const {
  process_status_t m{};
  m.utime = wall_utime();
  m.run_nonce = run_nonce_;
  m.role = role_;
  m.state = state;
  m.seq = seq_;
  m.acked_seq = acked_seq;
  m.message = wire::fit(message, wire::Check<process_status_t>::kMax_message);
  m.resends = resends;
  m.duplicates = duplicates;
  m.invalid = bus_.invalid() + invalid_content;
  m.foreign = bus_.foreign();
  m.conflicts = conflicts;
  m.unauthenticated = bus_.unauthenticated();
  m.contract_version = kContractVersion;
  return m;
}

void Node::heartbeat(bool force) {
  const std::int64_t now = mono_us();
  if (!force && last_heartbeat_us_ >= 0 && now - last_heartbeat_us_ < 100000) return;
  last_heartbeat_us_ = now;
  if (!bus_.run_known()) return;  // nothing to say before joining a run
  bus_.publish(ch_.status, status_message(state_, ""));
  if (on_heartbeat) on_heartbeat();
}

void Node::announce_failure(const std::string& message) {
  state_ = "failed";
  process_status_t m = status_message("failed", message);
  for (int i = 0; i < 3; ++i) {
    m.utime = wall_utime();
    bus_.publish(ch_.status, m);
  }
}

void Node::request_resend(const std::string& channel, std::int64_t seq) {
  resend_request_t m{};
  m.requester = role_;
  m.channel = wire::fit(channel, wire::Check<resend_request_t>::kMax_channel);
  m.seq = seq;
  bus_.publish(ch_.resend, m);
}

void Node::wait_for_run() {
  const std::int64_t start = mono_us();
  while (!bus_.run_known()) {
    check_peers();
    if (mono_us() - start > us(opt_.start_timeout_s))
      throw RunFailure("no heartbeat from the plant within " + seconds_text(opt_.start_timeout_s) +
                       " s to join its run (start the plant, or give every process the same --run-id)");
    bus_.poll(std::chrono::microseconds(us(opt_.resend_interval_s)));
  }
}

bool Node::on_conflict(const std::string& channel, std::int64_t seq, const char* type, const std::string& diff) {
  ++conflicts;
  const std::string what = "conflict on " + channel + " step " + std::to_string(seq) + ": two different " + type +
                           " for one step (" + diff +
                           " differ); another publisher on the bus, or a stale step number (an answer to "
                           "state k carrying seq < k)? (docs/security.md)";
  if (opt_.on_conflict == ConflictPolicy::kFail) throw RunFailure(what);
  // keep-first: every conflict is counted; the log names the first ten, then one a second.
  const std::int64_t now = mono_us();
  if (conflicts <= 10 || now - last_conflict_log_us_ > 1000000) {
    last_conflict_log_us_ = now;
    spdlog::error("{}: {}; kept the first ({} conflicts so far)", role_, what, conflicts);
  }
  return false;
}

bool is_run_role(const std::string& role) {
  return role == "plant" || role == "controller" || role == "trajectory" || role == "monitor";
}

void Node::check_peers() const {
  opt_.stop.check();
  if (!scenario_mismatch_.empty()) throw std::invalid_argument(scenario_mismatch_);
  for (const auto& [role, st] : peers_) {
    if (st.state != "failed" || !is_run_role(role)) continue;
    // Under feeddrive-launch a Ctrl-C reaches every process, but not at the same instant: a
    // peer's "interrupted by SIGINT" can arrive before this process's own signal. It is the
    // same interrupt, which the launcher reports once (this process stays quiet, exit 130).
    if (std::getenv(interrupt::kQuietEnv) != nullptr && st.message.rfind("interrupted by SIG", 0) == 0)
      throw interrupt::Interrupted(st.message == "interrupted by SIGTERM" ? SIGTERM : SIGINT);
    throw RunFailure(role + " failed at step " + std::to_string(st.seq) + ": " + st.message);
  }
}

const process_status_t* Node::peer(const std::string& role) const {
  const auto it = peers_.find(role);
  return it == peers_.end() ? nullptr : &it->second;
}

bool Node::peer_alive(const std::string& role, double seconds) const { return peer_alive_at(role, seconds, mono_us()); }

std::string Node::role_of_source(const std::string& source) const {
  const auto it = status_sources_.find(source);
  return it != status_sources_.end() && it->second.first == bus_.run_id() ? it->second.second : "";
}

bool Node::peer_alive_at(const std::string& role, double seconds, std::int64_t at_us) const {
  const process_status_t* p = peer(role);
  const auto seen = peer_seen_us_.find(role);
  return p != nullptr && seen != peer_seen_us_.end() && p->state != "failed" && at_us - seen->second <= us(seconds);
}

bool Node::monitor_done() const {
  const process_status_t* m = peer("monitor");
  return m != nullptr && (m->state == "done" || m->state == "failed");
}

void Node::linger(const std::function<void()>& every_100ms) {
  set_state("done");
  const std::int64_t start = mono_us();
  std::int64_t last_sent = start;
  // An attached monitor still recording may yet ask for what it missed: wait for it too, but
  // only while its acknowledgement moves (it advanced within the last second) and for at most
  // kAttachedHoldS after the run's monitor is done. A heartbeat saying "running" alone (a
  // forged one, or an attached monitor that hangs) holds nobody (docs/security.md, "Heartbeats").
  std::int64_t monitor_done_us = -1;
  const auto recording = [&] {
    const process_status_t* a = peer(kAttachedMonitorRole);
    const std::int64_t now = mono_us();
    if (monitor_done_us < 0) monitor_done_us = now;
    return a != nullptr && a->state == "running" && peer_alive(kAttachedMonitorRole, 1.0) &&
           now - attached_progress_us_ <= us(1.0) && now - monitor_done_us <= us(kAttachedHoldS);
  };
  while ((!monitor_done() || recording()) && mono_us() - start < us(opt_.linger_s)) {
    if (every_100ms && mono_us() - last_sent > 100000) {
      every_100ms();
      last_sent = mono_us();
    }
    bus_.poll(std::chrono::microseconds(20000));
    heartbeat();
  }
}

}  // namespace feeddrive::service
