#include "feeddrive/record/recorder.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "feeddrive/record/translate.hpp"

namespace feeddrive::record {

void Recorder::on_state(const drive_state_t& m, std::int64_t recv_us) {
  if (m.steps > 0) {
    steps_ = m.steps;
    ++steps_votes_[m.steps];
  }
  if (m.end_of_run) end_seen_ = true;
  rejected_ = std::max<std::int64_t>(rejected_, m.rejected_commands);
  missed_ = std::max<std::int64_t>(missed_, m.missed_deadlines);
  overruns_ = std::max<std::int64_t>(overruns_, m.overruns);
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
  if (const auto s = states_.find(m.seq); s != states_.end())
    lead_.add(static_cast<double>(s->second.recv_us - recv_us));
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
      add_row(s->second, &r->second.msg, nullptr, s1->second.msg, sink);
    } else {
      add_row(s->second, &r->second.msg, &c->second.msg, s1->second.msg, sink);
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

void Recorder::add_row(const Seen<drive_state_t>& s, const reference_t* r, const control_command_t* c,
                       const drive_state_t& s1, const sim::RecordSink& sink) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  control_command_t none{};
  if (c == nullptr) {
    none.seq = s.msg.seq;
    none.t = s.msg.t;
    none.u = none.u_unsaturated = none.sliding = none.z_estimate = nan;
    c = &none;
    ++commandless_;
  }
  reference_t no_ref{};
  if (r == nullptr) {
    no_ref.seq = s.msg.seq;
    no_ref.t = s.msg.t;
    no_ref.position = no_ref.velocity = no_ref.acceleration = no_ref.jerk = nan;
    r = &no_ref;
  }
  sink(to_record(s.msg, *r, *c, s1.previous));
}

std::size_t Recorder::flush_final(const sim::RecordSink& sink, bool need_reference) {
  std::size_t added = 0;
  if (whole_log_) {  // a short recording never flushed before: start from its lowest steps
    whole_log_ = false;
    maybe_start();
  }
  if (attach_ && !started_) return added;
  // The step count: the value most states carry.
  std::int64_t steps = -1;
  long votes = 0;
  for (const auto& [n, v] : steps_votes_)
    if (v > votes) steps = n, votes = v;
  steps_ = steps;
  for (;;) {
    if (steps_ >= 0 && next_ >= steps_) break;
    const Advance a = advance(sink, need_reference, true);
    if (a == Advance::kRow) ++added;
    if (a == Advance::kEnd) break;
  }
  return added;
}

std::size_t Recorder::skip_lost(const sim::RecordSink& sink) {
  if (!started() || (steps_ >= 0 && next_ >= steps_)) return 0;
  const Advance a = advance(sink, true, false);
  return (a == Advance::kRow ? 1 : 0) + (a == Advance::kWait ? 0 : flush(sink));
}

void Recorder::add_gap(std::int64_t first, std::int64_t last, const std::string& why) {
  if (!gaps_.empty() && gaps_.back().last + 1 == first) {
    gaps_.back().last = last;
  } else {
    gaps_.push_back({first, last, why});
  }
}

Recorder::Advance Recorder::advance(const sim::RecordSink& sink, bool need_reference, bool ended) {
  // Messages of steps outside the run (a corrupt sequence number) can never make a row.
  const auto in_run = [&](std::int64_t k) { return steps_ < 0 || k <= steps_; };
  const auto s = states_.find(next_);
  const auto s1 = states_.find(next_ + 1);
  const auto r = refs_.find(next_);
  const auto c = cmds_.find(next_);
  const bool have_ref = r != refs_.end();
  if (s != states_.end() && s1 != states_.end() && (have_ref || !need_reference)) {
    add_row(s->second, have_ref ? &r->second.msg : nullptr, c == cmds_.end() ? nullptr : &c->second.msg, s1->second.msg,
            sink);
    states_.erase(s);
    if (have_ref) refs_.erase(r);
    if (c != cmds_.end()) cmds_.erase(c);
    ++next_;
    ++rows_;
    return Advance::kRow;
  }
  // Step next_ cannot be completed. Where does the next step that might start?
  std::int64_t resume = std::numeric_limits<std::int64_t>::max();
  const auto after = states_.upper_bound(next_);
  if (after != states_.end() && in_run(after->first)) resume = after->first;
  if (s != states_.end() && s1 != states_.end()) resume = next_ + 1;  // only the reference is missing
  const std::string why = s == states_.end()    ? "no state " + std::to_string(next_) + " from the plant"
                          : s1 == states_.end() ? "no state " + std::to_string(next_ + 1) + " from the plant"
                                                : "no reference " + std::to_string(next_) + " from the trajectory";
  if (resume == std::numeric_limits<std::int64_t>::max()) {
    if (!ended) return Advance::kWait;
    // Nothing after it: the log ends before the run does.
    if (steps_ >= 0) add_gap(next_, steps_ - 1, why + (s == states_.end() ? " (the log ends)" : ""));
    next_ = steps_ >= 0 ? steps_ : next_;
    return Advance::kEnd;
  }
  add_gap(next_, resume - 1, why);
  next_ = resume;
  states_.erase(states_.begin(), states_.lower_bound(next_));
  refs_.erase(refs_.begin(), refs_.lower_bound(next_));
  cmds_.erase(cmds_.begin(), cmds_.lower_bound(next_));
  return Advance::kGap;
}

std::int64_t Recorder::missing_steps() const {
  std::int64_t n = 0;
  for (const Gap& g : gaps_) n += g.steps();
  return n;
}

std::string describe_gaps(const std::vector<Gap>& gaps, std::size_t max_listed) {
  std::int64_t total = 0;
  for (const Gap& g : gaps) total += g.steps();
  std::string out = std::to_string(total) + (total == 1 ? " step" : " steps") + " missing:";
  for (std::size_t i = 0; i < gaps.size() && i < max_listed; ++i) {
    const Gap& g = gaps[i];
    out += (i ? ", " : " ") + std::to_string(g.first) + (g.last > g.first ? "-" + std::to_string(g.last) : "") + " (" +
           g.why + ")";
  }
  if (gaps.size() > max_listed) out += " and " + std::to_string(gaps.size() - max_listed) + " more gaps";
  return out;
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

std::vector<Missing> Recorder::missing_until(std::int64_t upto, std::size_t per_kind) const {
  std::vector<Missing> out;
  std::size_t states = 0, commands = 0, refs = 0;
  std::int64_t last_block = -1;
  const auto s = states_.find(next_);
  const bool realtime = s != states_.end() && s->second.msg.realtime;
  const std::int64_t end = std::min(upto, next_ + 4096);
  for (std::int64_t k = next_; k <= end && (states < per_kind || commands < per_kind || refs < per_kind); ++k) {
    if (states < per_kind && !states_.count(k)) out.push_back({"state", "plant", k}), ++states;
    // The end-of-run marker (step steps_) has no reference of its own: none to ask for.
    if (refs < per_kind && k / 16 != last_block && (steps_ < 0 || k < steps_) && !refs_.count(k)) {
      out.push_back({"reference", "trajectory", k}), ++refs;
      last_block = k / 16;
    }
    if (commands < per_kind && k < upto && !realtime && !cmds_.count(k))
      out.push_back({"command", "controller", k}), ++commands;
  }
  return out;
}

double Recorder::steps_per_second() const {
  if (first_state_seq_ < 0 || highest_state_ <= first_state_seq_ || last_state_us_ <= first_state_us_) return 0.0;
  return static_cast<double>(highest_state_ - first_state_seq_) /
         (static_cast<double>(last_state_us_ - first_state_us_) * 1e-6);
}

}  // namespace feeddrive::record
