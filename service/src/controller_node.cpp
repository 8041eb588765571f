#include "feeddrive/service/controller_node.hpp"

#include <spdlog/spdlog.h>

#include "feeddrive/service/translate.hpp"

namespace feeddrive::service {

ControllerNode::ControllerNode(std::unique_ptr<controller::Controller> c, const NodeOptions& opt, lcm_t* shared_lcm)
    : Node("controller", opt, Receive::kDirect, shared_lcm),
      controller_(std::move(c)),
      commands_(bus(), channels().command) {
  bus().subscribe<drive_state_t>(channels().state, [this](const drive_state_t& m, std::int64_t now) {
    if (!admit(state_ledger_, channels().state, m.seq, m)) return;
    if (m.end_of_run) {
      end_ = true;
      return;
    }
    // Already answered. In lockstep the plant repeats a state whose command it lacks: send it
    // again. In real time the plant has moved on by then and repeats a state only for a
    // monitor's resend request (or state 0 in the start handshake, which is lockstep): an
    // answer would be late for the plant and would double the bus load of a monitor catching
    // up, on the chain's own core (measured: 87,000 duplicates and 5,500 deadline misses in a
    // 15,000-step run, docs/lcm-contract.md, "Real time against the machine").
    if (m.seq < next_seq_) {
      ++duplicates;
      if ((!options().realtime || m.seq == 0) && commands_.republish(m.seq)) ++resends;
      return;
    }
    if (pending_ && pending_->seq == m.seq) {
      ++duplicates;
      return;
    }
    // Lockstep: the plant publishes state k+1 only after a command k. A state beyond the next
    // unanswered one, when no other publisher's command for that step was seen either (it would
    // have come first: one socket, in order), is the plant's protocol error (a skipped or
    // reordered step number), never a loss here: named as the plant's, not left to look like the
    // controller's stall. With another publisher's command k (forged, or a second controller)
    // this controller still answers step k, and the plant or the monitor names the conflict.
    // In real time states go out every period whether answered or not: a lost one is a gap.
    // The first state heard, though, may be beyond step 0 with nothing seen before it: this
    // controller subscribed late, after another publisher had answered the earlier states (a
    // forger without --key, a second controller). That is not the plant's error: this
    // controller answers the state it has, and the plant or the monitor names the conflict.
    answered_by_others_.erase(answered_by_others_.begin(), answered_by_others_.lower_bound(next_seq_));
    if (!heard_state_ && m.seq > next_seq_)
      spdlog::warn(
          "controller: the first state heard is {}: states {}..{} went by before this controller "
          "listened, answered by another publisher",
          m.seq, next_seq_, m.seq - 1);
    const bool late_join = !heard_state_;
    heard_state_ = true;
    if (!options().realtime && !late_join && m.seq > next_seq_ && !answered_by_others_.count(next_seq_))
      throw RunFailure("protocol error of the plant: it published state " + std::to_string(m.seq) + " while step " +
                       std::to_string(next_seq_) +
                       " has no command yet (a skipped or out-of-order step number; "
                       "docs/external-plant.md)");
    // Waiting for a reference since the first unanswered state, not the newest: in real-time
    // mode a newer state replaces the pending one every period, and a request timed from the
    // newest would never go out.
    if (!pending_) pending_since_us_ = now;
    pending_ = m;
    try_answer();
  });
  bus().subscribe<reference_block_t>(channels().reference, [this](const reference_block_t& b, std::int64_t) {
    for (const reference_t& m : b.refs) {
      if (!admit(reference_ledger_, channels().reference, m.seq, m)) continue;
      if (m.seq < next_seq_ || refs_.count(m.seq)) {
        ++duplicates;
        continue;
      }
      refs_[m.seq] = m;
    }
    try_answer();
  });
  // Commands for steps not answered here are another publisher's (this controller's own come
  // back to it with seq < next_seq_). Kept only ahead of next_seq_, at most 1024 steps.
  bus().subscribe<control_command_t>(channels().command, [this](const control_command_t& m, std::int64_t) {
    if (m.seq >= next_seq_ && m.seq < next_seq_ + 1024) answered_by_others_.insert(m.seq);
  });
  on_resend_request = [this](const resend_request_t& r) {
    if (r.channel == commands_.channel() && commands_.republish(r.seq)) ++resends;
  };
}

void ControllerNode::try_answer() {
  if (!pending_) return;
  const auto it = refs_.find(pending_->seq);
  if (it == refs_.end()) return;
  const drive_state_t st = *pending_;
  pending_.reset();
  const controller::Truth truth = to_truth(st.truth);
  if (controller_->needs_truth() && !st.truth.valid)
    throw RunFailure(
        "the controller is configured with friction_state/grinding_state = true, but the plant "
        "sends no truth (hardware); use the observers");
  const controller::Command c =
      controller_->update(to_sample(it->second), to_measurement(st), st.truth.valid ? &truth : nullptr);
  commands_.publish(st.seq, to_message(st.seq, st.t, c));
  next_seq_ = st.seq + 1;
  set_seq(st.seq);
  last_progress_us_ = mono_us();
  refs_.erase(refs_.begin(), refs_.upper_bound(st.seq));
}

void ControllerNode::run() {
  // Below the plant (81): on a shared core the plant, woken by this command, runs at once rather
  // than after the rest of this process's turn (its send's return, its bookkeeping). Measured on
  // an isolated core (docs/lcm-contract.md, "An isolated core"): with the controller above, 164 of
  // the plant's 268 wake-ups later than 20 us waited for the controller; below, the plant's
  // overruns fell from 154-285 to 27-92 per 15,000 periods.
  enter_realtime_if_asked(80);
  set_state("running");
  last_progress_us_ = mono_us();
  const std::int64_t resend_us = us(options().resend_interval_s);
  while (!end_) {
    bus().poll(std::chrono::microseconds(resend_us));
    const std::int64_t now = mono_us();
    if (pending_ && now - pending_since_us_ > resend_us && now - last_ref_request_us_ > resend_us) {
      request_resend(channels().reference, pending_->seq);
      last_ref_request_us_ = now;
    }
    // Another role's failure first: it names the culprit (after this process was stopped, the
    // plant has failed naming it, and our own timeout would blame the plant).
    check_peers();
    const double limit = next_seq_ == 0 ? options().start_timeout_s : options().step_timeout_s;
    // As in the trajectory: a plant that still sends its heartbeat waits for another role and
    // will name it; never wait longer than three timeouts, though.
    const bool plant_waits =
        !pending_ && next_seq_ > 0 && peer_alive("plant", 0.5) && now - last_progress_us_ <= 3 * us(limit);
    if (now - last_progress_us_ > us(limit) && !plant_waits) {
      if (pending_)
        throw RunFailure("no reference from the trajectory for step " + std::to_string(pending_->seq) + " within " +
                         seconds_text(limit) + " s");
      throw RunFailure("no state from the plant for step " + std::to_string(next_seq_) + " within " +
                       seconds_text(limit) + " s");
    }
    check_peers();
    heartbeat();
  }
  linger();
}

}  // namespace feeddrive::service
