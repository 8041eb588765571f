#include "feeddrive/service/trajectory_node.hpp"

#include "feeddrive/service/translate.hpp"

namespace feeddrive::service {

TrajectoryNode::TrajectoryNode(const sim::Scenario& s, const NodeOptions& opt, lcm_t* shared_lcm)
    : Node("trajectory", opt, Receive::kBatched, shared_lcm),
      s_(s),
      reference_(sim::make_reference(s)),
      blocks_(bus(), channels().reference) {
  bus().subscribe<drive_state_t>(channels().state, [this](const drive_state_t& m, std::int64_t now) {
    if (!admit(state_ledger_, channels().state, m.seq, m)) return;
    if (m.end_of_run) {
      end_ = true;
      return;
    }
    if (m.seq <= highest_state_) {  // repeated state: whatever it needed got lost
      ++duplicates;
      // In real time a repeated state is the plant answering a monitor's resend request (the
      // controller asks for a missing reference itself, on the resend channel): no blocks.
      if (options().realtime && m.seq > 0) return;
      send_block(m.seq / kBlock, true);
      if ((m.seq + 1) % kBlock == 0) send_block((m.seq + 1) / kBlock, true);
      return;
    }
    highest_state_ = m.seq;
    last_progress_us_ = now;
    set_seq(m.seq);
    send_ahead(m.seq);
  });
  on_resend_request = [this](const resend_request_t& r) {
    if (r.channel != blocks_.channel() || r.seq < 0) return;
    // The requester lacks block seq/kBlock, and probably the blocks published after it too (it
    // started late, or its socket overflowed): send them again, not one request each, up to
    // one lead's worth (a monitor far behind asks again as it catches up).
    // In real time, while the plant runs, only the block asked for: a monitor on the chain's
    // core that fell behind would otherwise have 17 blocks sent for each of its requests, at
    // this process's real-time priority; it catches up after the end (linger()).
    const std::int64_t first = r.seq / kBlock;
    send_block(first, true);
    if (options().realtime && !end_) return;
    for (std::int64_t b = first + 1; b < std::min(next_block_, first + 1 + kLead / kBlock); ++b) send_block(b, true);
  };
}

void TrajectoryNode::send_block(std::int64_t b, bool resend) {
  const std::int64_t first = b * kBlock;
  if (first < 0 || first >= s_.steps()) return;
  if (blocks_.has(b)) {
    // Several requesters (controller, monitor, a repeated state) asking for the same block
    // within one resend interval get one copy.
    if (resend && blocks_.republish(b, us(options().resend_interval_s))) ++resends;
    return;
  }
  reference_block_t m{};
  m.first_seq = first;
  m.count = static_cast<std::int32_t>(std::min<std::int64_t>(kBlock, s_.steps() - first));
  for (std::int64_t k = first; k < first + m.count; ++k) {
    const double t = s_.time_of(k);
    m.refs.push_back(to_message(k, t, reference_->sample(t)));
  }
  blocks_.publish(b, m);
}

void TrajectoryNode::send_ahead(std::int64_t k) {
  for (; next_block_ <= (k + kLead) / kBlock && next_block_ * kBlock < s_.steps(); ++next_block_)
    send_block(next_block_, false);
}

void TrajectoryNode::run() {
  // Real time: the references feed the controller's every period, so the trajectory is part of
  // the loop too; below the plant (80) and the controller (81), above everything else. At
  // normal priority, pinned next to them (--cpus 0) on a busy machine, it starved for hundreds of
  // ms and the controller, waiting for its reference, missed thousands of deadlines.
  enter_realtime_if_asked(79);
  set_state("running");
  wait_for_run();  // every block must carry the run's identity
  // Everything, block 0 included, once the plant's first state shows that the run has started:
  // the plant publishes it only when the monitor is up (its flow control), so the monitor (and
  // its --lcm-log) sees the blocks in order from block 0, without asking for them again.
  last_progress_us_ = mono_us();
  while (!end_) {
    bus().poll(std::chrono::microseconds(us(options().resend_interval_s)));
    const double limit = highest_state_ < 0 ? options().start_timeout_s : options().step_timeout_s;
    // A plant that still sends its heartbeat is waiting for another role (the controller, the
    // monitor) and will time out naming it; blaming the plant here would hide the real cause.
    // Never wait longer than three timeouts, though.
    // Another role's failure first: it names the culprit (a stalled controller makes the plant
    // fail, and then the plant's heartbeat stops too; our own timeout would blame the plant).
    check_peers();
    // The plant has finished the run and no end-of-run state reached us: a controller that
    // answers without references let the plant run ahead of a late trajectory. The run is over;
    // linger() still answers the monitor's requests for the blocks it lacks.
    if (const process_status_t* p = peer("plant"); p != nullptr && p->state == "done" && p->seq >= s_.steps() - 1) {
      end_ = true;
      break;
    }
    const std::int64_t waited = mono_us() - last_progress_us_;
    const bool plant_waits = highest_state_ >= 0 && peer_alive("plant", 0.5) && waited <= 3 * us(limit);
    if (waited > us(limit) && !plant_waits)
      throw RunFailure("no state from the plant for step " + std::to_string(highest_state_ + 1) + " within " +
                       seconds_text(limit) + " s");
    check_peers();
    heartbeat();
  }
  linger();
}

}  // namespace feeddrive::service
