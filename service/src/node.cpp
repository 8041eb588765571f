#include "feeddrive/service/node.hpp"

#include <sched.h>
#include <sys/mman.h>
#include <sys/prctl.h>

#include <cerrno>
#include <csignal>

#include "feeddrive/common/interrupt.hpp"
#include <cstdio>
#include <cstring>
#include <ctime>

namespace feeddrive::service {
void install_signal_handlers() { interrupt::install_handlers(); }

int interrupted_by() { return interrupt::signal_number(); }

std::string enter_realtime(int priority) {
  ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  const bool locked = ::mlockall(MCL_CURRENT | MCL_FUTURE) == 0;
  const std::string lock = locked ? "memory locked" : std::string("memory not locked (mlockall: ") + std::strerror(errno) + ")";
  sched_param sp{};
  sp.sched_priority = priority;
  if (::sched_setscheduler(0, SCHED_FIFO, &sp) == 0) return "SCHED_FIFO " + std::to_string(priority) + ", " + lock;
  return std::string("normal scheduling (SCHED_FIFO not permitted: ") + std::strerror(errno) +
         "; needs root, CAP_SYS_NICE or an rtprio limit; expect missed deadlines at high rates), " + lock;
}

void sleep_until(std::int64_t target_us, std::int64_t spin_us) {
  const std::int64_t wake = target_us - spin_us;
  if (mono_us() < wake) {
    timespec ts{static_cast<time_t>(wake / 1000000), static_cast<long>((wake % 1000000) * 1000)};
    while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR && !interrupt::interrupted()) {
    }
  }
  while (mono_us() < target_us) {
  }
}

std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", s);
  return buf;
}

Node::Node(std::string role, const NodeOptions& opt, Receive receive)
    : role_(std::move(role)), opt_(opt), bus_(opt.lcm_url, receive), ch_(opt.prefix) {
  bus_.subscribe<process_status_t>(ch_.status, [this](const process_status_t& m, std::int64_t recv_us) {
    if (m.role == role_) return;
    peers_[m.role] = m;
    peer_seen_us_[m.role] = recv_us;
  });
  bus_.subscribe<resend_request_t>(ch_.resend, [this](const resend_request_t& m, std::int64_t) {
    if (on_resend_request) on_resend_request(m);
  });
}

void Node::heartbeat(bool force) {
  const std::int64_t now = mono_us();
  if (!force && last_heartbeat_us_ >= 0 && now - last_heartbeat_us_ < 100000) return;
  last_heartbeat_us_ = now;
  process_status_t m;
  m.utime = wall_utime();
  m.role = role_;
  m.state = state_;
  m.seq = seq_;
  m.acked_seq = acked_seq;
  m.message = "";
  m.resends = resends;
  m.duplicates = duplicates;
  m.invalid = bus_.invalid() + invalid_content;
  bus_.publish(ch_.status, m);
  if (on_heartbeat) on_heartbeat();
}

void Node::announce_failure(const std::string& message) {
  state_ = "failed";
  process_status_t m;
  m.role = role_;
  m.state = "failed";
  m.seq = seq_;
  m.acked_seq = acked_seq;
  m.message = message;
  m.resends = resends;
  m.duplicates = duplicates;
  m.invalid = bus_.invalid() + invalid_content;
  for (int i = 0; i < 3; ++i) {
    m.utime = wall_utime();
    bus_.publish(ch_.status, m);
  }
}

void Node::request_resend(const std::string& channel, std::int64_t seq) {
  resend_request_t m;
  m.requester = role_;
  m.channel = channel;
  m.seq = seq;
  bus_.publish(ch_.resend, m);
}

void Node::check_peers() const {
  if (const int sig = interrupt::signal_number(); sig != 0) throw RunFailure("interrupted by " + interrupt::signal_name(sig));
  for (const auto& [role, st] : peers_)
    if (st.state == "failed") throw RunFailure(role + " failed at step " + std::to_string(st.seq) + ": " + st.message);
}

const process_status_t* Node::peer(const std::string& role) const {
  const auto it = peers_.find(role);
  return it == peers_.end() ? nullptr : &it->second;
}

bool Node::peer_alive(const std::string& role, double seconds) const {
  const process_status_t* p = peer(role);
  const auto seen = peer_seen_us_.find(role);
  return p != nullptr && seen != peer_seen_us_.end() && p->state != "failed" &&
         mono_us() - seen->second <= us(seconds);
}

bool Node::monitor_done() const {
  const process_status_t* m = peer("monitor");
  return m != nullptr && (m->state == "done" || m->state == "failed");
}

void Node::linger(const std::function<void()>& every_100ms) {
  set_state("done");
  const std::int64_t start = mono_us();
  std::int64_t last_sent = start;
  while (!monitor_done() && mono_us() - start < us(opt_.linger_s)) {
    if (every_100ms && mono_us() - last_sent > 100000) {
      every_100ms();
      last_sent = mono_us();
    }
    bus_.poll(std::chrono::microseconds(20000));
    heartbeat();
  }
}

}  // namespace feeddrive::service
