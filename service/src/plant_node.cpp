#include "feeddrive/service/plant_node.hpp"

#include <spdlog/spdlog.h>

#include <thread>

#include "feeddrive/plant/command.hpp"
#include "feeddrive/service/translate.hpp"

namespace feeddrive::service {

PlantNode::PlantNode(const sim::Scenario& s, const NodeOptions& opt)
    : Node("plant", opt),
      s_(s),
      steps_(s.steps()),
      drive_(s.drive(), s.control_period),
      states_(bus(), channels().state),
      previous_(no_applied()) {
  if (!bus().run_known()) {
    bus().set_run_id(draw_run_id());
    spdlog::info("plant: run id {} (drawn: no --run-id given; the other processes join it from the plant's heartbeat)",
                 bus().run_id());
  }
  bus().subscribe<control_command_t>(channels().command, [this](const control_command_t& m, std::int64_t) {
    if (!admit(command_ledger_, channels().command, m.seq, m)) return;
    if (!command_ || m.seq > command_->seq) {
      command_ = m;
    } else {
      ++duplicates;
    }
  });
  on_resend_request = [this](const resend_request_t& r) {
    if (r.channel == states_.channel() && states_.republish(r.seq)) ++resends;
  };
}

drive_state_t PlantNode::make_state(std::int64_t k) {
  drive_state_t m{};
  m.seq = k;
  m.t = s_.time_of(k);
  m.steps = steps_;
  m.end_of_run = (k >= steps_);
  m.realtime = options().realtime;
  if (k < steps_) {
    const plant::Measurement meas = drive_.measure();  // draws the sensor noise: once per step
    m.x_measured = meas.x;
    m.v_measured = meas.v;
  } else {
    m.x_measured = drive_.state().x;  // not a sample: the end-of-run marker
    m.v_measured = drive_.state().v;
  }
  m.truth = to_truth_message(drive_.state());
  m.previous = previous_;
  m.rejected_commands = static_cast<std::int32_t>(rejected_);
  m.missed_deadlines = static_cast<std::int32_t>(missed_);
  m.safe_state = safe_state_;
  return m;
}

void PlantNode::publish_state(std::int64_t k) {
  states_.publish(k, make_state(k));
  set_seq(k);
}

void PlantNode::apply(std::int64_t k, double u) {
  const plant::Forces f = drive_.forces(u);
  previous_ = to_applied(k, u, f);
  drive_.advance(u, s_.time_of(k + 1));
}

void PlantNode::wait_for_monitor(std::int64_t k) {
  if (options().monitor_window <= 0) return;
  const std::int64_t start = mono_us();
  for (;;) {
    const process_status_t* m = peer("monitor");
    if (m != nullptr && k - m->acked_seq < options().monitor_window) return;
    check_peers();
    const double limit = m == nullptr ? options().start_timeout_s : options().step_timeout_s;
    if (mono_us() - start > us(limit))
      throw RunFailure("no acknowledgement from the monitor for step " +
                       std::to_string(std::max<std::int64_t>(k - options().monitor_window, 0)) + " within " +
                       seconds_text(limit) + " s (is feeddrive-monitor running?)");
    bus().poll(std::chrono::microseconds(us(options().resend_interval_s)));
    heartbeat();
  }
}

void PlantNode::run() {
  set_state("running");
  if (options().realtime) {
    run_realtime();
  } else {
    run_lockstep();
  }
  if (options().monitor_window > 0) {
    linger([this] { states_.republish(steps_); });  // the end-of-run marker must not get lost
  } else {
    set_state("done");  // no monitor to wait for
  }
}

void PlantNode::run_lockstep() {
  const std::int64_t resend_us = us(options().resend_interval_s);
  for (std::int64_t k = 0; k < steps_; ++k) {
    wait_for_monitor(k);
    publish_state(k);
    const std::int64_t start = mono_us();
    std::int64_t last_sent = start;
    while (!command_ || command_->seq < k) {
      const std::int64_t now = mono_us();
      if (now - last_sent >= resend_us) {
        states_.republish(k);
        ++resends;
        last_sent = now;
      }
      const double limit = k == 0 ? options().start_timeout_s : options().step_timeout_s;
      if (now - start > us(limit))
        throw RunFailure("no command from the controller for step " + std::to_string(k) + " within " +
                         seconds_text(limit) + " s");
      check_peers();
      heartbeat();
      bus().poll(std::chrono::microseconds(std::max<std::int64_t>(resend_us - (mono_us() - last_sent), 1)));
    }
    if (command_->seq > k) throw RunFailure("the controller answered step " + std::to_string(command_->seq) +
                                            " while the plant is at step " + std::to_string(k));
    const plant::AdmittedCommand a = plant::admit_command(command_->u, s_.plant.input_limit, 0.0);
    if (a.status != plant::CommandStatus::kApplied) {
      ++rejected_;
      spdlog::warn("plant: command {} for step {} {}", command_->u, k,
                   a.status == plant::CommandStatus::kRejected ? "rejected, 0 V applied" : "clipped to the input limit");
    }
    apply(k, a.u);
    heartbeat();
  }
  publish_state(steps_);
}

void PlantNode::run_realtime() {
  // Start handshake: state 0 waits for its command as in lockstep, so the clock starts only
  // when the controller, the trajectory and the monitor are all up.
  wait_for_monitor(0);
  publish_state(0);
  const std::int64_t hs_start = mono_us();
  std::int64_t last_sent = hs_start;
  while (!command_ || command_->seq < 0) {
    if (mono_us() - last_sent >= us(options().resend_interval_s)) {
      states_.republish(0);
      ++resends;
      last_sent = mono_us();
    }
    if (mono_us() - hs_start > us(options().start_timeout_s))
      throw RunFailure("no command from the controller for step 0 within " + seconds_text(options().start_timeout_s) + " s");
    check_peers();
    heartbeat();
    bus().poll(std::chrono::microseconds(us(options().resend_interval_s)));
  }
  const std::int64_t period_us = us(s_.control_period);
  const std::int64_t t0 = mono_us();
  for (std::int64_t k = 0; k < steps_; ++k) {
    if (k > 0) publish_state(k);
    const std::int64_t deadline = t0 + (k + 1) * period_us;
    while (mono_us() < deadline) {
      bus().poll(std::chrono::microseconds(std::max<std::int64_t>(deadline - mono_us(), 1)));
    }
    check_peers();
    heartbeat();
    double u = last_good_u_;
    bool good = false;
    if (command_ && command_->seq == k) {
      const plant::AdmittedCommand a = plant::admit_command(command_->u, s_.plant.input_limit, last_good_u_);
      if (a.status != plant::CommandStatus::kApplied) ++rejected_;
      if (a.status != plant::CommandStatus::kRejected) {
        u = a.u;
        good = true;
      }
    } else {
      ++missed_;
    }
    bad_in_a_row_ = good ? 0 : bad_in_a_row_ + 1;
    if (good) {
      last_good_u_ = u;
      if (safe_state_) spdlog::info("plant: valid commands again at step {}, leaving the safe state", k);
      safe_state_ = false;
    } else if (bad_in_a_row_ >= options().max_bad_commands && !safe_state_) {
      safe_state_ = true;
      spdlog::error("plant: {} missed or invalid commands in a row at step {}: safe state, zero thrust",
                    bad_in_a_row_, k);
    }
    if (safe_state_) u = 0.0;
    apply(k, u);
  }
  publish_state(steps_);
}


}  // namespace feeddrive::service
