#include "feeddrive/monitor/monitor_node.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/reference_block_t.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/sim/output.hpp"
#include "feeddrive/sim/summary.hpp"

namespace feeddrive::monitor {

using service::mono_us;
using service::us;

MonitorNode::MonitorNode(const sim::Scenario& s, const service::NodeOptions& opt, const MonitorOptions& mopt)
    : Node(mopt.attach ? "monitor-attached" : "monitor", opt, service::Receive::kBatched), s_(s), mopt_(mopt), rec_(mopt.attach) {
  if (mopt.attach) bus().join_first_seen();
  // Every message passes the conflict check first: a second, different message for a step is
  // never recorded (service::Node::admit).
  bus().subscribe<drive_state_t>(channels().state, [this](const drive_state_t& m, std::int64_t t) {
    if (admit(state_ledger_, channels().state, m.seq, m)) rec_.on_state(m, t);
  });
  bus().subscribe<reference_block_t>(channels().reference, [this](const reference_block_t& b, std::int64_t t) {
    for (const reference_t& m : b.refs)
      if (admit(reference_ledger_, channels().reference, m.seq, m)) rec_.on_reference(m, t);
  });
  bus().subscribe<control_command_t>(channels().command, [this](const control_command_t& m, std::int64_t t) {
    if (admit(command_ledger_, channels().command, m.seq, m)) rec_.on_command(m, t);
  });
  out_ = std::make_unique<sim::RunWriter>(mopt_.out_dir, s_, mopt_.attach ? "feeddrive-monitor --attach" : "feeddrive-monitor");
}

void MonitorNode::request_missing() {
  if (mopt_.attach) return;
  const std::int64_t now = mono_us();
  // Something is missing if later steps are already flowing, or nothing came for a while.
  const bool behind = rec_.highest_state() > rec_.next() + 1;
  const bool quiet = now - last_row_us_ > us(options().resend_interval_s) * 4;
  if (!behind && !quiet) return;
  if (now - last_request_us_ < us(options().resend_interval_s)) return;
  last_request_us_ = now;
  const std::string* channel = nullptr;
  for (const Missing& m : rec_.missing()) {
    if (m.what == "state") channel = &channels().state;
    if (m.what == "reference") channel = &channels().reference;
    if (m.what == "command") channel = &channels().command;
    // Only ask for what was sent already: the step after the newest state is not lost, it is
    // not there yet.
    if (m.seq > rec_.highest_state()) continue;
    if (m.what == "command" && m.seq == rec_.highest_state()) continue;
    request_resend(*channel, m.seq);
    ++lost_;
  }
}

void MonitorNode::progress(bool force) {
  const std::int64_t now = mono_us();
  if (!force && now - last_progress_us_ < us(mopt_.progress_interval_s)) return;
  last_progress_us_ = now;
  if (options().quiet) return;
  const double sim_t = static_cast<double>(rec_.next()) * s_.control_period;
  const double wall = static_cast<double>(now - start_us_) * 1e-6;
  const sim::Record& last = out_->last();
  const double err = out_->steps() == 0 ? 0.0 : (last.xd - (std::isnan(last.x) ? last.x_measured : last.x));
  std::fprintf(stderr, "\r[monitor] step %lld/%lld  t = %.4f s  real-time factor %.3f  e = %+.4g um   ",
               static_cast<long long>(rec_.next()), static_cast<long long>(rec_.steps() < 0 ? s_.steps() : rec_.steps()),
               sim_t, wall > 0 ? sim_t / wall : 0.0, err * 1e6);
  if (force) std::fprintf(stderr, "\n");
}

bool MonitorNode::run() {
  set_state("running");
  start_us_ = last_row_us_ = mono_us();
  std::string failure;
  try {
    for (;;) {
      // Off the critical path: the bus takes the messages in batches (Receive::kBatched), one
      // wake-up per millisecond instead of one per message.
      bus().poll(std::chrono::microseconds(1000));
      const std::size_t added = rec_.flush([this](const sim::Record& r) { out_->add(r); });
      const std::int64_t now = mono_us();
      if (added > 0) last_row_us_ = now;
      if (!mopt_.attach) {
        acked_seq = rec_.next();
        set_seq(rec_.next());
        // Acknowledge often enough that the plant's window never closes.
        const bool due = acked_seq - last_ack_sent_ >= std::max<long>(options().monitor_window / 4, 1);
        heartbeat(due);
        if (due) last_ack_sent_ = acked_seq;
      }
      progress(false);
      if (rec_.complete()) break;
      request_missing();
      check_peers();
      const double limit = rec_.next() == 0 && rec_.highest_state() < 0 ? options().start_timeout_s : options().step_timeout_s;
      if (now - last_row_us_ > us(limit)) {
        if (mopt_.attach && rec_.highest_state() < 0)
          throw service::RunFailure("no message on " + channels().state + " within " + service::seconds_text(limit) + " s");
        std::string who;
        for (const Missing& m : rec_.missing())
          who += (who.empty() ? "" : ", ") + m.what + " " + std::to_string(m.seq) + " from the " + m.role;
        throw service::RunFailure("step " + std::to_string(rec_.next()) + " incomplete for " + service::seconds_text(limit) +
                                  " s: no " + who);
      }
    }
  } catch (const service::RunFailure& e) {
    failure = e.what();
  } catch (const std::runtime_error& e) {  // writing a row failed (disk full, ...)
    failure = e.what();
  }
  progress(true);
  // Not written (folder, disk, gnuplot): the run failed too, whatever the steps did.
  return finish(failure.empty(), failure) && failure.empty();
}

bool MonitorNode::finish(bool completed, const std::string& failure) {
  const double wall_time_s = static_cast<double>(mono_us() - start_us_) * 1e-6;
  const sim::Summary sum = out_->summary().summary(wall_time_s, {});

  std::int64_t resends_total = resends, duplicates_total = duplicates + rec_.duplicates(), invalid_total = bus().invalid();
  // Foreign, conflicting and unauthenticated messages: the most any one process saw (each
  // process hears the same bus; the monitor hears every channel, the others fewer).
  std::int64_t foreign = bus().foreign(), conflicts_seen = conflicts, unauthenticated = bus().unauthenticated();
  for (const char* role : {"plant", "controller", "trajectory"}) {
    if (const process_status_t* p = peer(role)) {
      resends_total += p->resends;
      duplicates_total += p->duplicates;
      invalid_total += p->invalid;
      foreign = std::max(foreign, p->foreign);
      conflicts_seen = std::max(conflicts_seen, p->conflicts);
      unauthenticated = std::max(unauthenticated, p->unauthenticated);
    }
  }
  const auto lat = [](const stats::StreamingQuantile& v, double q) { return v.quantile(q); };
  summary_.scenario = s_.name;
  summary_.completed = completed;
  summary_.failure = failure;
  summary_.steps = static_cast<std::int64_t>(sum.steps);
  summary_.stopped_at_seq = rec_.next();
  summary_.sim_time_s = sum.sim_time_s;
  summary_.wall_time_s = wall_time_s;
  summary_.position_error_max_abs_m = sum.position_error_max_abs_m;
  summary_.position_error_rms_m = sum.position_error_rms_m;
  summary_.velocity_error_max_abs_mps = sum.velocity_error_max_abs_mps;
  summary_.control_min = sum.control_min;
  summary_.control_max = sum.control_max;
  summary_.control_total_variation = sum.control_total_variation;
  summary_.resends = resends_total;
  summary_.lost = lost_;
  summary_.duplicates = duplicates_total;
  summary_.invalid = invalid_total;
  summary_.rejected_commands = rec_.rejected_commands();
  summary_.deadline_misses = rec_.missed_deadlines();
  summary_.foreign = foreign;
  summary_.conflicts = conflicts_seen;
  summary_.unauthenticated = unauthenticated;
  summary_.latency_state_to_command_p50_us = lat(rec_.latency_state_to_command(), 0.5);
  summary_.latency_state_to_command_p99_us = lat(rec_.latency_state_to_command(), 0.99);
  summary_.latency_command_to_state_p50_us = lat(rec_.latency_command_to_state(), 0.5);
  summary_.latency_command_to_state_p99_us = lat(rec_.latency_command_to_state(), 0.99);
  summary_.reference_lead_p50_us = lat(rec_.reference_lead(), 0.5);
  summary_.reference_lead_p1_us = lat(rec_.reference_lead(), 0.01);

  nlohmann::ordered_json j;
  auto& l = j["lockstep"];
  l["mode"] = options().realtime ? "realtime" : "lockstep";
  l["completed"] = completed;
  l["failure"] = failure;
  l["steps_expected"] = rec_.steps() < 0 ? s_.steps() : rec_.steps();
  l["stopped_at_step"] = rec_.next();
  l["resends"] = resends_total;
  l["lost"] = lost_;
  l["duplicates"] = duplicates_total;
  l["invalid_messages"] = invalid_total;
  l["rejected_commands"] = rec_.rejected_commands();
  l["deadline_misses"] = rec_.missed_deadlines();
  l["run_id"] = bus().run_id();
  l["authenticated"] = bus().authenticated();
  l["foreign_messages"] = foreign;
  l["conflicts"] = conflicts_seen;
  l["unauthenticated_messages"] = unauthenticated;
  l["steps_without_command"] = rec_.commandless_rows();
  l["steps_per_second"] = rec_.steps_per_second();
  {
    // One step on the wire: state + command + 1/16 of a block of 16 references, each an LCM
    // datagram of an 8-byte header, the channel name and its NUL, and the encoded message (with
    // its 32-byte mac when the run is authenticated).
    const int mac = bus().authenticated() ? static_cast<int>(service::MessageAuth::kMacSize) : 0;
    const auto packet = [mac](const std::string& channel, int payload) {
      return 8 + static_cast<int>(channel.size()) + 1 + payload + mac;
    };
    reference_block_t block{};
    block.count = 16;
    block.refs.resize(16);
    l["bytes_per_step"] = packet(channels().state, drive_state_t().getEncodedSize()) +
                          packet(channels().reference, block.getEncodedSize()) / 16 +
                          packet(channels().command, control_command_t().getEncodedSize());
  }
  l["safe_state"] = rec_.safe_state();
  const auto hop = [&](const char* name, const stats::StreamingQuantile& v) {
    l["latency_us"][name] = {{"p50", lat(v, 0.5)}, {"p99", lat(v, 0.99)}, {"samples", v.count()}};
  };
  hop("state_to_command", rec_.latency_state_to_command());
  hop("command_to_state", rec_.latency_command_to_state());
  l["reference_lead_us"] = {{"p50", lat(rec_.reference_lead(), 0.5)},
                            {"p1", lat(rec_.reference_lead(), 0.01)},
                            {"samples", rec_.reference_lead().count()}};
  for (auto* v : {&l["latency_us"]["state_to_command"], &l["latency_us"]["command_to_state"], &l["reference_lead_us"]})
    for (const char* q : {"p50", "p99", "p1"})
      if (v->contains(q) && std::isnan((*v)[q].get<double>())) (*v)[q] = nullptr;

  bool written = true;
  std::string why = failure;
  try {
    out_->finish(sum, mopt_.plots, j.dump());
  } catch (const std::exception& e) {
    spdlog::error("monitor: writing {} failed: {}", output::shown(mopt_.out_dir), e.what());
    written = false;
    completed = false;
    if (why.empty()) why = std::string("results not written: ") + e.what();
    summary_.completed = false;
    summary_.failure = why;
  }
  bus().publish(channels().summary, summary_);
  if (completed) {
    set_state("done");
  } else {
    announce_failure(why);
  }
  if (!options().quiet)
    spdlog::info("monitor: {} steps recorded{} -> {}", sum.steps,
                 completed ? "" : " (stopped at step " + std::to_string(rec_.next()) + ": " + why + ")",
                 output::shown(mopt_.out_dir));
  return written;
}

}  // namespace feeddrive::monitor
