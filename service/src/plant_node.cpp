#include "feeddrive/service/plant_node.hpp"

#include <spdlog/spdlog.h>

#include <cstring>
#include <thread>

#include "feeddrive/plant/command.hpp"
#include "feeddrive/service/translate.hpp"

namespace feeddrive::service {
namespace {
// Real time: command k must arrive this long before w_{k+1}, so that the plant can integrate
// the rest of the period and prepare state k+1 before w_{k+1}: a fifth of the period, at most
// 25 us (the plant's integrate + prepare takes 10-20 us on the development VM, measured as the
// monitor's command_to_state hop in lockstep, which includes a wake-up).
std::int64_t realtime_guard_us(std::int64_t period_us) { return std::min<std::int64_t>(period_us / 5, 25); }
}  // namespace

PlantNode::PlantNode(const sim::Scenario& s, const NodeOptions& opt, lcm_t* shared_lcm)
    : Node("plant", opt, Receive::kDirect, shared_lcm),
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
  bus().subscribe<control_command_t>(channels().command, [this](const control_command_t& m, std::int64_t recv_us) {
    if (!admit(command_ledger_, channels().command, m.seq, m)) return;
    if (options().realtime) arrived_.emplace_back(m, recv_us);
    // A command for a step already answered that differs from the first one (a stale step
    // number, or another publisher) is a conflict (admit): counted and named.
    if (!command_ || m.seq > command_->seq) {
      command_ = m;
    } else {
      ++duplicates;  // a repeat (real time: also a late command, counted as a missed deadline)
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
  m.overruns = static_cast<std::int32_t>(overruns_);
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

void PlantNode::wait_for_pace(std::int64_t due_us) {
  for (std::int64_t now = mono_us(); now < due_us; now = mono_us()) {
    bus().poll(std::chrono::microseconds(due_us - now));  // resend requests, heartbeats meanwhile
    check_peers();
    heartbeat();
  }
}

void PlantNode::run_lockstep() {
  const std::int64_t resend_us = us(options().resend_interval_s);
  // --max-rate: each state at least 1/max_rate after the previous one (no catching up after a
  // stall: a burst is what a slow recorder cannot take).
  const std::int64_t pace_us = options().max_rate > 0 ? static_cast<std::int64_t>(1e6 / options().max_rate) : 0;
  std::int64_t due_us = 0;
  for (std::int64_t k = 0; k < steps_; ++k) {
    wait_for_monitor(k);
    if (pace_us > 0) {
      wait_for_pace(due_us);
      due_us = mono_us() + pace_us;
    }
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
      // Another role's failure first: it names the culprit. A controller that still sends its
      // heartbeat is waiting for someone else (the trajectory) and will name them; a stalled or
      // dead one sends none. Never wait longer than three timeouts, though.
      check_peers();
      const bool controller_waits = k > 0 && peer_alive("controller", 0.5) && now - start <= 3 * us(limit);
      if (now - start > us(limit) && !controller_waits)
        throw RunFailure("no command from the controller for step " + std::to_string(k) + " within " +
                         seconds_text(limit) + " s");
      heartbeat();
      bus().poll(std::chrono::microseconds(std::max<std::int64_t>(resend_us - (mono_us() - last_sent), 1)));
    }
    if (command_->seq > k)
      throw RunFailure("the controller answered step " + std::to_string(command_->seq) +
                       " while the plant is at step " + std::to_string(k));
    const plant::AdmittedCommand a = plant::admit_command(command_->u, s_.plant.input_limit, 0.0);
    if (a.status != plant::CommandStatus::kApplied) {
      ++rejected_;
      spdlog::warn(
          "plant: command {} for step {} {}", command_->u, k,
          a.status == plant::CommandStatus::kRejected ? "rejected, 0 V applied" : "clipped to the input limit");
    }
    apply(k, a.u);
    heartbeat();
  }
  publish_state(steps_);
}

double PlantNode::sim_time_of(std::int64_t mono) const { return static_cast<double>(mono - t0_us_) * 1e-6; }

bool PlantNode::take_commands(std::int64_t k, double t_end) {
  bool got_k = false;  // command k arrived (valid or not)
  for (const auto& [c, recv_us] : arrived_) {
    if (c.seq <= newest_seq_) continue;  // a repeat (counted by the handler), or older than one acting
    newest_seq_ = c.seq;
    if (c.seq > k)
      throw RunFailure("the controller answered step " + std::to_string(c.seq) + " while the plant is at step " +
                       std::to_string(k));
    const bool on_time = c.seq == k;
    const plant::AdmittedCommand a = plant::admit_command(c.u, s_.plant.input_limit, last_good_u_);
    if (a.status != plant::CommandStatus::kApplied) ++rejected_;
    const bool good = a.status != plant::CommandStatus::kRejected;
    if (on_time) {
      got_k = true;
      bad_in_a_row_ = good ? 0 : bad_in_a_row_ + 1;
      if (good && safe_state_) {
        spdlog::info("plant: valid commands again at step {}, leaving the safe state", k);
        safe_state_ = false;
      }
    }
    if (!good || safe_state_) continue;  // in the safe state only a command on time acts
    // Zero-order hold from the arrival: [now, t_a] with the old input, then the new one.
    // Arrivals within 1 ns of the current time or of the period's end are taken as there: the
    // clock has 1 us resolution, so only rounding makes them differ, and CVODE refuses an
    // interval of a few ulps (CV_TOO_CLOSE).
    const double ta = std::min(sim_time_of(recv_us), t_end);
    if (ta > drive_.time() + 1e-9 && ta < t_end - 1e-9) drive_.advance(u_now_, ta);
    u_now_ = last_good_u_ = a.u;
  }
  arrived_.clear();
  return got_k;
}

void PlantNode::run_realtime() {
  enter_realtime_if_asked(81);  // above the controller (80): controller_node.cpp
  command_.reset();
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
      throw RunFailure("no command from the controller for step 0 within " + seconds_text(options().start_timeout_s) +
                       " s");
    check_peers();
    heartbeat();
    bus().poll(std::chrono::microseconds(us(options().resend_interval_s)));
  }
  const std::int64_t period_us = us(s_.control_period);
  const std::int64_t guard_us = realtime_guard_us(period_us);
  t0_us_ = mono_us();
  for (auto& [c, recv_us] : arrived_) recv_us = t0_us_;  // command 0 came before the clock started
  for (std::int64_t k = 0; k < steps_; ++k) {
    // State k went out at w_k. Wait for command k until the deadline; every command that comes
    // switches the input at its arrival.
    const double t_next = s_.time_of(k + 1);
    const std::int64_t deadline = t0_us_ + (k + 1) * period_us - guard_us;
    bool got_k = take_commands(k, t_next);
    for (std::int64_t now = mono_us(); !got_k && now < deadline; now = mono_us()) {
      bus().poll(std::chrono::microseconds(deadline - now));
      got_k = take_commands(k, t_next);
    }
    if (!got_k) {
      ++missed_;
      ++bad_in_a_row_;
    }
    {
      if (bad_in_a_row_ >= options().max_bad_commands && !safe_state_) {
        safe_state_ = true;
        u_now_ = 0.0;
        spdlog::error("plant: {} missed or invalid commands in a row at step {}: safe state, zero thrust",
                      bad_in_a_row_, k);
      }
    }
    if (safe_state_) u_now_ = 0.0;
    // The rest of the period with the input held now; state k+1 is ready before w_{k+1}.
    previous_ = to_applied(k, u_now_, drive_.forces(u_now_));
    drive_.advance(u_now_, t_next);
    if (k + 1 < steps_) {
      drive_state_t next = make_state(k + 1);
      const std::int64_t w = t0_us_ + (k + 1) * period_us;
      sleep_until(w, options().realtime_spin_us, options().stop);
      const std::int64_t late = mono_us() - w;
      // An overrun: the plant itself (its timer, its integration, a descheduled virtual CPU)
      // starts the period more than the guard late. Catching up would give the controller less
      // than T - guard for each of the next periods and turn one stall of the simulator into a
      // run of missed deadlines (and the safe state); a real drive's clock does not stall. So the
      // plant moves its clock on by the delay (the simulated drive waits with it: simulated time
      // stays k*T) and counts the overrun apart from the controller's deadline misses.
      if (late > guard_us) {
        t0_us_ += late;
        next.overruns = static_cast<std::int32_t>(++overruns_);
      }
      next.start_late_us = static_cast<float>(late);
      states_.publish(k + 1, next);  // first thing in the period
      set_seq(k + 1);
    }
    check_peers();
    heartbeat();
  }
  publish_state(steps_);
}

}  // namespace feeddrive::service
