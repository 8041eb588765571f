#include "feeddrive/service/node.hpp"

#include <cstdio>

#include "feeddrive/common/interrupt.hpp"

namespace feeddrive::service {

void install_signal_handlers() { interrupt::install(); }

int interrupted_by() { return interrupt::signal_number(); }

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
  interrupt::check();
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
