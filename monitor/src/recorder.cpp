#include "feeddrive/monitor/recorder.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "feeddrive/service/translate.hpp"

namespace feeddrive::monitor {

void Recorder::on_state(const drive_state_t& m, std::int64_t recv_us) {
  if (m.steps > 0) steps_ = m.steps;
  if (m.end_of_run) end_seen_ = true;
  rejected_ = std::max<std::int64_t>(rejected_, m.rejected_commands);
  missed_ = std::max<std::int64_t>(missed_, m.missed_deadlines);
  if (m.seq > highest_state_) {
    highest_state_ = m.seq;
    safe_state_ = m.safe_state;
    if (first_state_seq_ < 0) {
      first_state_seq_ = m.seq;
      first_state_us_ = recv_us;
    }
    last_state_us_ = recv_us;
  }
  if (m.seq < next_ || states_.count(m.seq)) {
    ++duplicates_;
    return;
  }
  states_[m.seq] = {m, recv_us};
  if (const auto r = refs_.find(m.seq); r != refs_.end()) lead_.add(static_cast<double>(recv_us - r->second.recv_us));
  maybe_start();
  const auto c = cmds_.find(m.seq - 1);
  if (c != cmds_.end() && recv_us >= c->second.recv_us) lat_cs_.add(static_cast<double>(recv_us - c->second.recv_us));
}

void Recorder::on_reference(const reference_t& m, std::int64_t recv_us) {
  if (m.seq < next_ || refs_.count(m.seq)) {
    ++duplicates_;
    return;
  }
  refs_[m.seq] = {m, recv_us};
  if (first_ref_seq_ < 0 || (whole_log_ && m.seq < first_ref_seq_)) first_ref_seq_ = m.seq;
  maybe_start();
  if (const auto s = states_.find(m.seq); s != states_.end()) lead_.add(static_cast<double>(s->second.recv_us - recv_us));
}

void Recorder::on_command(const control_command_t& m, std::int64_t recv_us) {
  if (m.seq < next_ || cmds_.count(m.seq)) {
    ++duplicates_;
    return;
  }
  cmds_[m.seq] = {m, recv_us};
  const auto s = states_.find(m.seq);
  if (s != states_.end() && recv_us >= s->second.recv_us) lat_sc_.add(static_cast<double>(recv_us - s->second.recv_us));
}

void Recorder::maybe_start() {
  // Attach mode: references arrive in blocks ahead of the states, so the first row is the first
  // step for which both the state and the reference can have been seen: max(first state, first
  // reference). What came before it is dropped.
  if (!attach_ || started_ || whole_log_ || first_state_seq_ < 0 || first_ref_seq_ < 0) return;
  next_ = std::max(first_state_seq_, first_ref_seq_);
  started_ = true;
  states_.erase(states_.begin(), states_.lower_bound(next_));
  refs_.erase(refs_.begin(), refs_.lower_bound(next_));
  cmds_.erase(cmds_.begin(), cmds_.lower_bound(next_));
}

std::size_t Recorder::flush(const sim::RecordSink& sink) {
  std::size_t added = 0;
  if (whole_log_) {  // the whole recording is in: start from its lowest steps
    whole_log_ = false;
    maybe_start();
  }
  if (attach_ && !started_) return 0;
  for (;;) {
    if (steps_ >= 0 && next_ >= steps_) break;
    const auto s = states_.find(next_);
    const auto r = refs_.find(next_);
    const auto c = cmds_.find(next_);
    const auto s1 = states_.find(next_ + 1);
    if (s == states_.end() || r == refs_.end() || s1 == states_.end()) break;
    if (c == cmds_.end()) {
      // Real time only: the step ran on a stale command; wait one more step for a late one.
      const bool passed = s1->second.msg.end_of_run || states_.count(next_ + 2) != 0;
      if (!s->second.msg.realtime || !passed) break;
      control_command_t none{};
      none.seq = next_;
      none.t = s->second.msg.t;
      none.u = none.u_unsaturated = none.sliding = none.z_estimate = std::numeric_limits<double>::quiet_NaN();
      sink(service::to_record(s->second.msg, r->second.msg, none, s1->second.msg.previous));
      ++commandless_;
    } else {
      sink(service::to_record(s->second.msg, r->second.msg, c->second.msg, s1->second.msg.previous));
      cmds_.erase(c);
    }
    states_.erase(s);
    refs_.erase(r);
    ++next_;
    ++added;
    ++rows_;
  }
  return added;
}

std::vector<Missing> Recorder::missing() const {
  std::vector<Missing> out;
  if (steps_ >= 0 && next_ >= steps_) return out;
  if (!states_.count(next_)) out.push_back({"state", "plant", next_});
  if (!refs_.count(next_)) out.push_back({"reference", "trajectory", next_});
  const auto s = states_.find(next_);
  const bool realtime = s != states_.end() && s->second.msg.realtime;
  if (!cmds_.count(next_) && !realtime) out.push_back({"command", "controller", next_});
  if (!states_.count(next_ + 1)) out.push_back({"state", "plant", next_ + 1});
  return out;
}

double Recorder::steps_per_second() const {
  if (first_state_seq_ < 0 || highest_state_ <= first_state_seq_ || last_state_us_ <= first_state_us_) return 0.0;
  return static_cast<double>(highest_state_ - first_state_seq_) / (static_cast<double>(last_state_us_ - first_state_us_) * 1e-6);
}

}  // namespace feeddrive::monitor
