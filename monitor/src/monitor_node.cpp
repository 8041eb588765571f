#include "feeddrive/monitor/monitor_node.hpp"
#include "feeddrive/service/loggers.hpp"
#include "feeddrive/wire.hpp"

#include <spdlog/spdlog.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/common/text_file.hpp"
#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/output/gnuplot.hpp"
#include "feeddrive/reference_block_t.hpp"
#include "feeddrive/service/contract.hpp"
#include "feeddrive/service/translate.hpp"
#include "feeddrive/sim/output.hpp"
#include "feeddrive/sim/summary.hpp"

namespace feeddrive::monitor {

using service::mono_us;
using service::us;

MonitorNode::MonitorNode(const sim::Scenario& s, const service::NodeOptions& opt, const MonitorOptions& mopt,
                         lcm_t* shared_lcm)
    : Node(mopt.attach ? service::kAttachedMonitorRole : "monitor", opt, service::Receive::kBatched, shared_lcm),
      s_(s),
      mopt_(mopt),
      rec_(mopt.attach),
      // Histograms: bins of T/20 up to 2T (5 us at 10 kHz).
      timing_(s.control_period * 1e6 / 20.0) {
  if (mopt.attach) bus().join_first_seen();
  subscribe_run_channels();
  if (!mopt_.lcm_log.empty()) open_lcm_log(opt);
  serve_run_info(opt);
  watch_bus_events();
  stop_ = opt.stop;
  out_ = std::make_unique<sim::RunWriter>(mopt_.out_dir, s_,
                                          mopt_.attach ? "feeddrive-monitor --attach" : "feeddrive-monitor", opt.stop);
  out_->keep_data_on_interrupt(true);  // what the monitor recorded cannot be made again
}

void MonitorNode::subscribe_run_channels() {
  // Every message passes the conflict check first: a second, different message for a step is
  // never recorded (service::Node::admit).
  bus().subscribe<drive_state_t>(channels().state, [this](const drive_state_t& m, std::int64_t t) { on_state(m, t); });
  bus().subscribe<reference_block_t>(channels().reference, [this](const reference_block_t& b, std::int64_t t) {
    named_.last_admitted_us["trajectory"] = mono_us();
    for (const reference_t& m : b.refs)
      if (admit(ledgers_.reference, channels().reference, m.seq, m)) rec_.on_reference(m, t);
  });
  bus().subscribe<control_command_t>(channels().command,
                                     [this](const control_command_t& m, std::int64_t t) { on_command(m, t); });
}

void MonitorNode::on_state(const drive_state_t& m, std::int64_t t) {
  when_.last_state = mono_us();
  if (!admit(ledgers_.state, channels().state, m.seq, m)) return;
  named_.last_admitted_us["plant"] = when_.last_state;
  if (m.previous.seq >= 0)
    commands_.applied[static_cast<std::uint64_t>(m.previous.seq) % commands_.applied.size()] = {m.previous.seq,
                                                                                                m.previous.u};
  if (commands_.conflict && !commands_.conflict->applied_known && m.previous.seq == commands_.conflict->step) {
    commands_.conflict->applied_known = true;  // what the plant applied over the conflicted step
    commands_.conflict->applied_u = m.previous.u;
  }
  rec_.on_state(m, t);
  on_state_timing(m, t);
}

// The local process that owns the UDP port of an "IP:PORT" source ("" if none is found).
std::string MonitorNode::process_on_source(const std::string& source) {
  const auto colon = source.rfind(':');
  return colon == std::string::npos ? "" : service::local_process_on_udp_port(std::atoi(source.c_str() + colon + 1));
}

void MonitorNode::note_source(const std::string& source) {
  if (commands_.source_process.count(source) || commands_.source_process.size() >= 16) return;
  commands_.source_process[source] = process_on_source(source);
}

void MonitorNode::on_command(const control_command_t& m, std::int64_t t) {
  SentCommand& first = commands_.first[static_cast<std::uint64_t>(m.seq) % commands_.first.size()];
  const SentCommand sent{m.seq, m.u, bus().current_source()};
  note_source(sent.sender);
  try {
    if (!admit(ledgers_.command, channels().command, m.seq, m)) return;
  } catch (const service::RunFailure&) {
    // A forged command raced the controller's (or the reverse): keep both and who sent them;
    // the step stays in the record (its state k+1 says what the plant applied).
    if (!commands_.conflict && first.seq == m.seq) {
      commands_.conflict = CommandConflict{m.seq, first, sent, false, 0.0};
      const auto& a = commands_.applied[static_cast<std::uint64_t>(m.seq) % commands_.applied.size()];
      if (a.first == m.seq) commands_.conflict->applied_known = true, commands_.conflict->applied_u = a.second;
      for (SentCommand* c : {&commands_.conflict->first, &commands_.conflict->second}) {
        // "IP:PORT" of its UDP source, and the local process that owns that port if any.
        auto known = commands_.source_process.find(c->sender);
        if (known != commands_.source_process.end() && known->second.empty())
          known->second = process_on_source(c->sender);  // once more: it may have bound since
        if (known != commands_.source_process.end() && !known->second.empty()) c->sender += " " + known->second;
        // Gone before it could be looked up (the run fails at once on a conflict, and a loaded
        // monitor reads its backlog late): the role whose heartbeats came from that socket.
        else if (const std::string r = role_of_source(c->sender); !r.empty())
          c->sender += " (the " + r + "'s socket, by its heartbeats; no local process owns it now)";
      }
    }
    throw;
  }
  if (first.seq != m.seq) first = sent;
  named_.last_admitted_us["controller"] = mono_us();
  rec_.on_command(m, t);
  on_command_timing(m, t);
}

void MonitorNode::open_lcm_log(const service::NodeOptions& opt) {
  if (!bus().batched())
    throw std::invalid_argument("--lcm-log " + mopt_.lcm_log +
                                ": needs a udpm:// LCM URL (the monitor logs what its socket receives), not " +
                                opt.lcm_url);
  output::check_outside(mopt_.lcm_log, "--lcm-log", mopt_.out_dir);
  log_.writer = std::make_unique<record::LcmLogWriter>(mopt_.lcm_log);
  const std::string run_channels = opt.prefix + "_";
  bus().set_tap([this, run_channels](std::string_view ch, const std::uint8_t* d, std::size_t n, std::int64_t utime) {
    if (ch.compare(0, run_channels.size(), run_channels) != 0 || !log_.error.empty()) return;
    try {
      log_.writer->write(ch, d, n, utime);
    } catch (const std::exception& e) {
      log_.error = e.what();
    }
  });
}

// The run's self-description (run_info_t): the monitor is in every run (a hardware driver may
// take the plant's role, never the monitor's) and off the step's path. At the start, every
// second (10 heartbeats) until it exits, and on a resend request for the channel. An attached
// monitor only listens.
void MonitorNode::serve_run_info(const service::NodeOptions& opt) {
  if (mopt_.attach) return;
  // The scenario's hash as the launcher read it (--scenario-hash), else of the file read here.
  info_ = service::to_run_info(s_, opt, opt.scenario_hash);  // run_id: stamped by the bus
  on_heartbeat = [this] {
    if (heartbeats_++ % 10 == 0) publish_info();
  };
  on_resend_request = [this](const resend_request_t& r) {
    if (r.channel == channels().info) publish_info();
  };
}

void MonitorNode::watch_bus_events() {
  service::BusEvents ev;
  ev.foreign = [this](const std::string& ch, std::int64_t id, const std::string& r) { on_foreign(ch, id, r); };
  ev.unauthenticated = [this](const std::string& ch, const std::uint8_t* d, std::size_t n) {
    on_unauthenticated(ch, d, n);
  };
  ev.undecodable = [this](const std::string& ch, const std::uint8_t* d, std::size_t n, const std::string& why) {
    on_undecodable(ch, d, n, why);
  };
  bus().set_events(std::move(ev));
  on_peer_status = [this](const process_status_t& m) {
    note_source(bus().current_source());  // a participant's heartbeats and commands share its socket
    check_peer_status(m);
  };
  on_peer_status_back = [this](const process_status_t& m) {  // "starting" after "running": a restart?
    if (m.role == "plant" && m.state != "failed") plant_went_back(m);
  };
}

void MonitorNode::publish_info() {
  info_.utime = service::wall_utime();
  info_.run_nonce = run_nonce();
  info_.current_step = rec_.highest_state() < 0 ? -1 : rec_.next();
  bus().publish(channels().info, info_);
}

void MonitorNode::fail_for(const std::string& role, const std::string& why, bool unless_role_alive) {
  // A message the bus drops (unsigned, another run, another contract) from a role whose own,
  // admitted process is alive is an extra sender on the bus, maybe an attacker: named and counted,
  // never a reason to end the run (docs/security.md). It fails the run only when it stands in for
  // a role nobody else fills: then the run could never go on.
  // Filled: its heartbeat within the last second, or its own valid messages (at the start of a
  // run an attacker's first messages can come before the role's first heartbeat reaches us).
  const auto admitted = named_.last_admitted_us.find(role);
  const bool filled =
      peer_alive(role, 1.0) || (admitted != named_.last_admitted_us.end() && mono_us() - admitted->second < 1000000);
  if (unless_role_alive && filled) return;
  if (service::is_run_role(role) && !mopt_.attach && failure_.empty()) failure_ = why;
}

void MonitorNode::on_foreign(const std::string& channel, std::int64_t run_id, const std::string& sender) {
  const std::string who_role = sender.empty() ? service::publisher_of(channels(), channel) : sender;
  // One line per sender (run id 0: per role, whatever the channel): the count is in the summary.
  const std::string key = run_id == 0 ? "run id 0 " + who_role : "foreign " + channel + " " + std::to_string(run_id);
  if (named_.count[key]++ > 0) return;
  const std::string who = who_role.empty() ? "a participant" : "the " + who_role;
  if (run_id == 0) {
    const std::string why = who + " publishes run id 0 on " + channel +
                            ": a client older than run ids (contract version 1)? Stamp run_info_t.run_id (this run: " +
                            std::to_string(bus().run_id()) + ") on every message; this run speaks contract version " +
                            std::to_string(service::kContractVersion) + " (docs/lcm-contract.md, Versions)";
    spdlog::error("{}: {}", role(), why);
    fail_for(who_role, why);
    return;
  }
  // A plant of another run while this run's plant is silent: the drive restarted (it drew a new
  // run id). A restarted plant cannot rejoin (docs/external-plant.md, "Restarts"). Silent on
  // the time line the messages came in (their receive times), not the monitor's: a loaded
  // monitor reading a backlog would otherwise find the plant "silent" with its newer heartbeats
  // still queued, and take a replayed log's first plant message for a restart (CI, stop 29).
  if (who_role == "plant" && named_.plant_seq_seen >= 0 && !peer_alive_at("plant", 0.3, bus().current_recv_us())) {
    const std::string why =
        "the plant restarted: a plant with a new run id " + std::to_string(run_id) + " appeared on " + channel +
        " after this run's plant (run id " + std::to_string(bus().run_id()) + ") went silent after state " +
        std::to_string(rec_.highest_state()) +
        "; a restarted drive cannot rejoin a run: start a new run (docs/external-plant.md, Restarts)";
    spdlog::error("{}: {}", role(), why);
    fail_for("plant", why, false);  // its own test above: silent for 0.3 s
    return;
  }
  spdlog::warn(
      "{}: {} of another run (run id {}; this run {}) publishes on {}: a second run on this group, a participant "
      "given the wrong --run-id, or a replayed log; its messages are ignored (give one run another --prefix or "
      "--lcm-url: docs/security.md)",
      role(), who, run_id, bus().run_id(), channel);
}

void MonitorNode::on_unauthenticated(const std::string& channel, const std::uint8_t* d, std::size_t n) {
  // The mac is the message's tail: mac_size (int16) 0 and no mac bytes means unsigned.
  const bool unsigned_msg = n >= 2 && d[n - 2] == 0 && d[n - 1] == 0;
  std::string who_role = service::publisher_of(channels(), channel);
  if (channel == channels().status) who_role = service::heartbeat_role(d, n);
  const std::string key = "unauthenticated " + channel + " " + who_role + (unsigned_msg ? " unsigned" : " badmac");
  const std::int64_t count = ++named_.count[key];
  const std::int64_t now = mono_us();
  const std::int64_t first = named_.first_unauthenticated_us.emplace(key, now).first->second;
  const std::string who = who_role.empty() ? "a participant" : "the " + who_role;
  const std::string why =
      who +
      (unsigned_msg ? " publishes unsigned messages on " : " publishes messages with a mac that does not verify on ") +
      channel + ", but this run is authenticated with --key " + options().key_file +
      (unsigned_msg ? ": give it the same key" : ": another key, or forged; give it the same key") +
      " (docs/security.md)";
  // This monitor's own role is never someone else's to fill: such a message is forged. Named
  // once, counted, never a reason to end the run.
  if (who_role == role()) {
    if (count == 1)
      spdlog::warn("{}: {} message on {} in this monitor's own role: forged; ignored (counted as unauthenticated)",
                   role(), unsigned_msg ? "an unsigned" : "a wrongly signed", channel);
    return;
  }
  if (count == 1) spdlog::error("{}: {}", role(), why);
  // A participant, not stray or forged datagrams: its own heartbeats (on the status channel, in
  // its role), three of them over at least a second, while no process of this run fills the
  // role (fail_for: the real process, once up, fills it and the sender is only named). Unsigned
  // data messages alone (junk on a channel) are counted and named, never a reason to end the
  // run. An unsigned participant can never take part, so the run fails now instead of at a
  // timeout that would not mention the key.
  if (channel == channels().status && count >= 3 && now - first >= 1000000) fail_for(who_role, why);
}

void MonitorNode::on_undecodable(const std::string& channel, const std::uint8_t* d, std::size_t n,
                                 const std::string& why_invalid) {
  if (const auto older = service::older_contract(channels(), channel, d, n)) {
    const std::string key = "older " + channel + " " + older->role + " " + std::to_string(older->version);
    if (named_.count[key]++ > 0) return;
    const std::string why = service::describe_older(*older, channel);
    spdlog::error("{}: {}", role(), why);
    fail_for(older->role, why);
    return;
  }
  const std::string key = "undecodable " + channel;
  if (named_.count[key]++ == 0)
    spdlog::warn(
        "{}: dropped a message on {} that is not valid: {} ({} bytes; counted in invalid_messages, further "
        "ones on this channel silently)",
        role(), channel, why_invalid, n);
}

void MonitorNode::check_peer_status(const process_status_t& m) {
  if (m.contract_version != service::kContractVersion) {
    const std::string key = "version " + m.role + " " + std::to_string(m.contract_version);
    if (named_.count[key]++ == 0 && m.contract_version == 0) {
      // Built from these types but never set: it decodes, so it may well work; named, not failed.
      spdlog::warn(
          "{}: the {} sends contract_version 0 in its heartbeat: set it to {} (docs/lcm-contract.md, Versions)", role(),
          m.role, service::kContractVersion);
    } else if (named_.count[key] == 1) {
      const std::string why = "the " + m.role + " speaks contract version " + std::to_string(m.contract_version) +
                              "; this run speaks " + std::to_string(service::kContractVersion) +
                              ": rebuild it with this feeddrive's lcmtypes/ (docs/lcm-contract.md, Versions)";
      spdlog::error("{}: {}", role(), why);
      fail_for(m.role, why, false);
    }
  }
  if (m.role != "plant") return;
  // A heartbeat step far beyond every state recorded (more than the flow-control window and
  // 100 steps in flight) is not the plant's: forged. It is not taken as the plant's progress,
  // so it cannot make the real heartbeats look as if they went back.
  if (plant_step_implausible(m.seq)) {
    if (named_.count["implausible plant heartbeat"]++ == 0)
      spdlog::warn("{}: a heartbeat of the plant claims step {}, beyond every state recorded ({}): forged; ignored",
                   role(), m.seq, rec_.highest_state());
    return;
  }
  if (named_.plant_seq_seen > 1 && m.seq < named_.plant_seq_seen - 1 && m.state != "failed") {
    plant_went_back(m);
    return;
  }
  named_.plant_seq_seen = std::max(named_.plant_seq_seen, m.seq);
}

// A plant step beyond every state recorded by more than the flow-control window and 100 steps
// in flight is not the plant's: forged.
bool MonitorNode::plant_step_implausible(std::int64_t seq) const {
  return seq > rec_.highest_state() + std::max<std::int64_t>(options().monitor_window, 0) + 100;
}

// A plant whose heartbeat goes back (its step, or "starting" after "running"): a new process
// with the same run id that starts again (docs/external-plant.md, "Restarts").
// - With --key that cannot be: a restarted plant draws a new nonce, so its run id on the wire
//   is another (on_foreign names it). A heartbeat of this run that goes back is a replay of
//   the run's own signed heartbeats: named once and ignored (docs/security.md, "Heartbeats").
// - Without a key a restart and a forged heartbeat look the same, and anyone on the bus can
//   send either, as they can send a forged command (docs/security.md: detected, not
//   prevented). A record that joins two drives' motions must not pass as complete, so the run
//   fails, and the line says both.
void MonitorNode::plant_went_back(const process_status_t& m) {
  if (named_.plant_seq_seen < 0) return;  // no plant of this run heard yet: nothing to restart
  // After the plant's own "done" or "failed" nothing restarts the run (and the Node ignored the
  // heartbeat); a step beyond every state recorded is forged (check_peer_status).
  if (const process_status_t* p = peer("plant"); p != nullptr && (p->state == "done" || p->state == "failed")) return;
  if (plant_step_implausible(m.seq)) return;
  if (!options().key_file.empty()) {
    if (named_.count["plant heartbeat back"]++ == 0)
      spdlog::warn(
          "{}: a signed heartbeat of the plant went back (step {} '{}' after step {}): a replay of this run's "
          "own heartbeats (a restarted plant would have drawn a new nonce); ignored",
          role(), m.seq, m.state, named_.plant_seq_seen);
    return;
  }
  const std::string why =
      "the plant restarted: its heartbeat went back from step " + std::to_string(named_.plant_seq_seen) + " to " +
      std::to_string(m.seq) + " (" + m.state +
      "); a restarted drive cannot rejoin a run: start a new run (docs/external-plant.md, Restarts). "
      "Without --key a forged heartbeat looks the same (docs/security.md)";
  if (named_.count["restart"]++ == 0) spdlog::error("{}: {}", role(), why);
  fail_for("plant", why, false);
}

// Latency histograms from the first receive time of each message (one clock: the kernel's
// receive stamps of this socket): state k -> command k, command k -> state k+1, and (real time)
// how late state k went out. Only the steps in flight are kept.
void MonitorNode::on_state_timing(const drive_state_t& m, std::int64_t t) {
  if (m.end_of_run || m.seq <= timing_.pruned || timing_.state_recv.count(m.seq)) return;
  timing_.state_recv[m.seq] = t;
  if (options().realtime && m.seq >= 1)
    timing_.start_lateness.add(static_cast<double>(m.start_late_us));  // state 0: the start handshake
  if (const auto c = timing_.command_recv.find(m.seq - 1); c != timing_.command_recv.end() && t >= c->second)
    timing_.command_to_state.add(static_cast<double>(t - c->second));
  prune_timing(m.seq);
}

void MonitorNode::on_command_timing(const control_command_t& m, std::int64_t t) {
  if (m.seq <= timing_.pruned || timing_.command_recv.count(m.seq)) return;
  timing_.command_recv[m.seq] = t;
  if (const auto s = timing_.state_recv.find(m.seq); s != timing_.state_recv.end() && t >= s->second)
    timing_.state_to_command.add(static_cast<double>(t - s->second));
  prune_timing(m.seq);
}

void MonitorNode::prune_timing(std::int64_t seq) {
  constexpr std::int64_t kKeep = 4096;  // steps in flight: far more than a step's messages are apart
  if (seq - timing_.pruned < 2 * kKeep) return;
  timing_.pruned = seq - kKeep;
  timing_.state_recv.erase(timing_.state_recv.begin(), timing_.state_recv.upper_bound(timing_.pruned));
  timing_.command_recv.erase(timing_.command_recv.begin(), timing_.command_recv.upper_bound(timing_.pruned));
}

void MonitorNode::request_missing() {
  if (!rec_.started()) return;  // attach mode: the first step is not chosen yet
  const std::int64_t now = mono_us();
  // Something is missing if later steps are already flowing, or nothing came for a while.
  const bool behind = rec_.highest_state() > rec_.next() + 1;
  const bool quiet = now - when_.last_row > us(options().resend_interval_s) * 4;
  if (!behind && !quiet) return;
  if (now - when_.last_request < us(options().resend_interval_s)) return;
  when_.last_request = now;
  if (asking_.seq != rec_.next()) {
    asking_.seq = rec_.next();
    asking_.since_us = now;
    asking_.requests = 0;
  }
  ++asking_.requests;
  // Only ask for what was sent already: the step after the newest state is not lost, it is not
  // there yet. A monitor far behind (an attached one whose socket overflowed) asks for up to
  // kPerRound messages of each kind a round, not one.
  // In real time, while the plant runs, two of each kind a round: every re-sent message costs the
  // chain's processes a send or a wake-up on their core, and a monitor that lost thousands
  // (starved on that core) would take the chain's time; the rest comes after the end, while the
  // plant and the trajectory linger (docs/lcm-contract.md, "Real time against the machine").
  constexpr std::size_t kPerRound = 64;
  constexpr std::size_t kPerRoundInRealTime = 2;
  const std::size_t per_round = options().realtime && !rec_.end_seen() ? kPerRoundInRealTime : kPerRound;
  for (const record::Missing& m : rec_.missing_until(rec_.highest_state(), per_round)) {
    const std::string& channel = m.what == "state"       ? channels().state
                                 : m.what == "reference" ? channels().reference
                                                         : channels().command;
    request_resend(channel, m.seq);
    ++asking_.lost;
  }
}

bool MonitorNode::attached_stalled(std::int64_t now, double limit) {
  const auto sink = [this](const sim::Record& r) { out_->add(r); };
  if (now - when_.last_state > us(limit)) {
    // Nothing for `limit`: the run (or the log played back) is over, or gone. Whatever can
    // still be completed is recorded, the rest is a gap.
    rec_.flush_final(sink);
    if (!rec_.end_seen())
      throw service::RunFailure("no message on " + channels().state + " for " + service::seconds_text(limit) +
                                " s after step " + std::to_string(rec_.highest_state()) +
                                ": the run stopped before its end");
    return true;
  }
  // States still come in: a step asked for this often and this long is not kept any more.
  if (asking_.seq == rec_.next() && asking_.requests >= kLostAfterRequests &&
      now - asking_.since_us >= us(kLostAfter_s)) {
    const std::size_t gaps = rec_.gaps().size();
    if (rec_.skip_lost(sink) > 0 || rec_.gaps().size() != gaps) when_.last_row = now;
    if (rec_.gaps().size() != gaps && !options().quiet)
      spdlog::warn("{}: {} (not re-sent after {} requests)", role(), record::describe_gaps({rec_.gaps().back()}),
                   asking_.requests);
  }
  return rec_.complete();
}

void MonitorNode::progress(bool force) {
  const std::int64_t now = mono_us();
  if (!force && now - when_.last_progress < us(mopt_.progress_interval_s)) return;
  when_.last_progress = now;
  if (options().quiet || !mopt_.progress) return;
  const double sim_t = static_cast<double>(rec_.next()) * s_.control_period;
  const double wall = static_cast<double>(now - when_.start) * 1e-6;
  const sim::Record& last = out_->last();
  const double err = out_->steps() == 0 ? 0.0 : (last.xd - (std::isnan(last.x) ? last.x_measured : last.x));
  char line[200];
  std::snprintf(line, sizeof line, "[monitor] step %lld/%lld  t = %.4f s  real-time factor %.3f  e = %+.4g um",
                static_cast<long long>(rec_.next()), static_cast<long long>(steps_expected()), sim_t,
                wall > 0 ? sim_t / wall : 0.0, err * 1e6);
  mopt_.progress(line, force);
}

void MonitorNode::watch_rate_and_loggers(std::int64_t now) {
  if (rate_.since_us >= 0 && now - rate_.since_us < 1000000) return;
  if (rate_.since_us >= 0)
    rate_.peak = std::max(rate_.peak, static_cast<double>(rec_.next() - rate_.since_step) * 1e6 /
                                          static_cast<double>(now - rate_.since_us));
  rate_.since_us = now;
  rate_.since_step = rec_.next();
  for (const service::StockLogger& l : service::stock_loggers_on(options().lcm_url)) {
    bool known = false;
    for (const service::StockLogger& k : rate_.loggers) known = known || k.pid == l.pid;
    if (known) continue;
    rate_.loggers.push_back(l);  // reported at the end with the peak rate (one line)
  }
}

std::size_t MonitorNode::flush_rows() {
  return rec_.flush([this](const sim::Record& r) { out_->add(r); });
}

std::int64_t MonitorNode::steps_expected() const { return rec_.steps() < 0 ? s_.steps() : rec_.steps(); }

bool MonitorNode::run() {
  set_state("running");
  when_.start = when_.last_row = mono_us();
  std::string failure;
  try {
    record_in_real_time_if_asked();
  } catch (const service::RunFailure& e) {
    failure = record_after_failure(e.what());
  } catch (const interrupt::Interrupted& e) {
    // Ctrl-C: what was recorded is still written (completed: false), without plots, and a second
    // Ctrl-C stops that too; then the process exits as interrupted (128 + signal).
    progress(true);
    stop_ = stop_.renewed();
    mopt_.plots = false;
    finish(false, e.what());
    throw interrupt::Interrupted(e.signal());
  } catch (const std::runtime_error& e) {  // writing a row failed (disk full, ...)
    failure = e.what();
  } catch (const std::invalid_argument& e) {  // the record cannot fit the disk (RunWriter, first rows)
    failure = e.what();
    too_big_ = true;
  }
  if (log_.writer) failure = close_lcm_log(failure);
  progress(true);
  // Not written (folder, disk, gnuplot): the run failed too, whatever the steps did.
  return finish(failure.empty(), failure) && failure.empty();
}

// Real time: the record is part of the run. At normal priority (it was nice 10) on the chain's
// core, the monitor fell behind whenever anything else ran, its socket overflowed, and its resend
// requests loaded the chain further: 5,000 of 15,000 deadlines missed in some runs (docs/lcm-
// contract.md, "Real time against the machine"). SCHED_FIFO 78, below the trajectory (79), the
// controller (80) and the plant (81), lets only the chain preempt it. Its memory grows with the
// record, so it is not locked; the output is written at normal priority again.
void MonitorNode::record_in_real_time_if_asked() {
  if (!options().realtime || mopt_.attach) return record_until_end();
  enter_realtime_if_asked(78, false);
  struct Normal {
    ~Normal() { service::leave_realtime(); }
  } normal_after;
  record_until_end();
}

void MonitorNode::record_until_end() {
  for (;;) {
    // Off the critical path: the bus takes the messages in batches (Receive::kBatched), one
    // wake-up per millisecond instead of one per message.
    bus().poll(std::chrono::microseconds(1000));
    const std::size_t added = flush_rows();
    const std::int64_t now = mono_us();
    if (added > 0) when_.last_row = now;
    // Every second the rows so far go to the staged file: a SIGKILLed monitor loses at most
    // the last second (the launcher moves the staged folder beside --out).
    if (now - when_.last_file_flush >= 1000000) {
      out_->flush();
      when_.last_file_flush = now;
    }
    heartbeat_progress();
    progress(false);
    watch_rate_and_loggers(now);
    if (!failure_.empty()) throw service::RunFailure(failure_);
    if (!log_.error.empty()) throw service::RunFailure(log_.error);
    if (rec_.complete()) return;
    request_missing();
    check_peers();
    const double limit =
        rec_.next() == 0 && rec_.highest_state() < 0 ? options().start_timeout_s : options().step_timeout_s;
    if (mopt_.attach && rec_.highest_state() >= 0 && now - when_.last_row > us(kLostAfter_s)) {
      if (attached_stalled(now, limit)) return;
      continue;
    }
    if (now - when_.last_row > us(limit)) check_step_timeout(now, limit);
  }
}

void MonitorNode::heartbeat_progress() {
  set_seq(rec_.next());
  if (mopt_.attach) {
    heartbeat();  // "running": the publishers linger after the end while it still records
    return;
  }
  acked_seq = rec_.next();
  // Acknowledge often enough that the plant's window never closes.
  const bool due = acked_seq - asking_.last_ack_sent >= std::max<long>(options().monitor_window / 4, 1);
  heartbeat(due);
  if (due) asking_.last_ack_sent = acked_seq;
}

void MonitorNode::check_step_timeout(std::int64_t now, double limit) {
  if (mopt_.attach && rec_.highest_state() < 0)
    throw service::RunFailure("no message on " + channels().state + " within " + service::seconds_text(limit) + " s");
  // A role whose heartbeat still comes is waiting on another and runs its own timeout: it
  // will name the culprit (check_peers), as the trajectory and the controller do. So wait for
  // it (at most three timeouts), then name only the roles that went silent.
  const std::vector<record::Missing> missing = rec_.missing();
  bool someone_waits = false;
  for (const record::Missing& m : missing) someone_waits = someone_waits || peer_alive(m.role, 0.5);
  if (someone_waits && now - when_.last_row <= 3 * us(limit)) return;
  std::string silent, all;
  for (const record::Missing& m : missing) {
    const std::string what = m.what + " " + std::to_string(m.seq) + " from the " + m.role;
    all += (all.empty() ? "" : ", ") + what;
    if (!peer_alive(m.role, 0.5)) silent += (silent.empty() ? "" : ", ") + what;
  }
  const std::string& who = silent.empty() ? all : silent;
  throw service::RunFailure("step " + std::to_string(rec_.next()) + " incomplete for " + service::seconds_text(limit) +
                            " s: no " + who);
}

std::string MonitorNode::record_after_failure(std::string failure) {
  // A command conflict: wait (at most 0.5 s) for the state that says which command the plant
  // applied, so that the step is recorded and the summary can name it.
  for (const std::int64_t until = mono_us() + 500000;
       commands_.conflict && !commands_.conflict->applied_known && mono_us() < until;) {
    try {
      bus().poll(std::chrono::microseconds(20000));
    } catch (const std::exception&) {}
  }
  if (const std::string a = applied_command_text(); !a.empty()) failure += "; " + a;
  // The record reaches the last step completed before the failure: the batch that failed was
  // dispatched whole (Bus::poll rethrows after it), and what is still queued on the socket (a
  // monitor behind the run when another role's failure arrives) is taken too, up to 100 batches.
  for (int i = 0; i < 100; ++i) {
    bool more = false;
    try {
      more = bus().poll(std::chrono::microseconds(0));
    } catch (const std::exception&) {
      more = true;  // another conflict or failure in this batch: it was dispatched all the same
    }
    try {
      flush_rows();
    } catch (const std::exception&) {
      break;
    }
    if (!more) break;
  }
  return failure;
}

std::string MonitorNode::close_lcm_log(std::string failure) {
  // Whatever else is still queued (the end-of-run state's repeats) goes in, then the file is
  // closed before the run is announced done.
  bus().poll(std::chrono::microseconds(0));
  bus().set_tap({});
  try {
    log_.writer->close();
    if (!options().quiet) spdlog::info("monitor: {} LCM events -> {}", log_.writer->events(), log_.writer->path());
  } catch (const std::exception& e) {
    if (log_.error.empty()) log_.error = e.what();
  }
  if (!log_.error.empty() && failure.empty()) failure = log_.error;
  return failure;
}

std::string MonitorNode::applied_command_text() const {
  if (!commands_.conflict) return "";
  const CommandConflict& c = *commands_.conflict;
  const auto from = [](const SentCommand& s) { return s.sender.empty() ? std::string("an unknown sender") : s.sender; };
  if (!c.applied_known)
    return "the plant's state after step " + std::to_string(c.step) +
           " did not come (it stopped on the conflict before "
           "applying either command, or that state was lost): u = " +
           service::seconds_text(c.first.u) + " V from " + from(c.first) +
           " or u = " + service::seconds_text(c.second.u) + " V from " + from(c.second);
  const bool first = c.applied_first();
  const SentCommand& a = first ? c.first : c.second;
  const SentCommand& o = first ? c.second : c.first;
  return "the plant applied u = " + service::seconds_text(a.u) + " V from " + from(a) + " at step " +
         std::to_string(c.step) + " (the other command, u = " + service::seconds_text(o.u) + " V, came from " +
         from(o) + "; the step is in the record)";
}

MonitorNode::BusCounts MonitorNode::bus_counts() {
  BusCounts c;
  c.resends = resends;
  c.duplicates = duplicates + rec_.duplicates();
  c.invalid = bus().invalid();
  // Foreign, conflicting and unauthenticated messages: the most any one process saw (each
  // process hears the same bus; the monitor hears every channel, the others fewer).
  c.foreign = bus().foreign();
  c.conflicts = conflicts;
  c.unauthenticated = bus().unauthenticated();
  for (const char* role : {"plant", "controller", "trajectory"}) {
    if (const process_status_t* p = peer(role)) {
      c.resends += p->resends;
      c.duplicates += p->duplicates;
      c.invalid += p->invalid;
      c.foreign = std::max(c.foreign, p->foreign);
      c.conflicts = std::max(c.conflicts, p->conflicts);
      c.unauthenticated = std::max(c.unauthenticated, p->unauthenticated);
    }
  }
  return c;
}

// In real time a state_to_command beyond T - guard is a deadline miss, and
// period_start_lateness is how late the plant sent each state after its period start, on its
// own clock (drive_state_t.start_late_us: its timer wake-up and spin).
MonitorNode::LatencyHistograms MonitorNode::latency_histograms() const {
  LatencyHistograms l{{"state_to_command", "command_to_state"}, {timing_.state_to_command, timing_.command_to_state}};
  if (options().realtime) {
    l.names.push_back("period_start_lateness");
    l.h.push_back(timing_.start_lateness);
  }
  return l;
}

void MonitorNode::fill_summary(bool completed, const std::string& failure, const sim::Summary& sum, double wall_time_s,
                               const BusCounts& c) {
  summary_.scenario = wire::fit(s_.name, wire::Check<run_summary_t>::kMax_scenario);
  summary_.completed = completed;
  summary_.failure = wire::fit(failure, wire::Check<run_summary_t>::kMax_failure);
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
  summary_.resends = c.resends;
  summary_.lost = asking_.lost;
  summary_.duplicates = c.duplicates;
  summary_.invalid = c.invalid;
  summary_.rejected_commands = rec_.rejected_commands();
  summary_.deadline_misses = rec_.missed_deadlines();
  summary_.foreign = c.foreign;
  summary_.conflicts = c.conflicts;
  summary_.unauthenticated = c.unauthenticated;
  summary_.latency_state_to_command_p50_us = rec_.latency_state_to_command().quantile(0.5);
  summary_.latency_state_to_command_p99_us = rec_.latency_state_to_command().quantile(0.99);
  summary_.latency_command_to_state_p50_us = rec_.latency_command_to_state().quantile(0.5);
  summary_.latency_command_to_state_p99_us = rec_.latency_command_to_state().quantile(0.99);
  summary_.reference_lead_p50_us = rec_.reference_lead().quantile(0.5);
  summary_.reference_lead_p1_us = rec_.reference_lead().quantile(0.01);
}

// The "lockstep" object of summary.json, key by key in its documented order (docs/lcm-contract.md);
// the parts that are more than a key (the conflict, the loggers, the latencies) are functions.
nlohmann::ordered_json MonitorNode::lockstep_json(bool completed, const std::string& failure, const sim::Summary& sum,
                                                  double wall_time_s, const BusCounts& c,
                                                  const LatencyHistograms& hists) {
  nlohmann::ordered_json l;
  l["mode"] = options().realtime ? "realtime" : "lockstep";
  l["completed"] = completed;
  l["failure"] = failure;
  l["steps_expected"] = steps_expected();
  l["stopped_at_step"] = rec_.next();
  l["resends"] = c.resends;
  l["lost"] = asking_.lost;
  l["duplicates"] = c.duplicates;
  l["invalid_messages"] = c.invalid;
  // The monitor hears every channel of the run: its own count per channel says where they came
  // ("" : datagrams without LCM's framing). invalid_messages adds the other processes' counts.
  l["invalid_messages_by_channel"] = nlohmann::ordered_json::object();
  for (const auto& [ch, n] : bus().invalid_by_channel())
    l["invalid_messages_by_channel"][ch.empty() ? "(not LCM)" : ch] = n;
  l["rejected_commands"] = rec_.rejected_commands();
  l["deadline_misses"] = rec_.missed_deadlines();
  l["plant_overruns"] = rec_.plant_overruns();
  l["run_id"] = bus().run_id();
  l["authenticated"] = bus().authenticated();
  l["foreign_messages"] = c.foreign;
  l["conflicts"] = c.conflicts;
  if (commands_.conflict) l["command_conflict"] = command_conflict_json(*commands_.conflict);
  l["unauthenticated_messages"] = c.unauthenticated;
  l["steps_without_command"] = rec_.commandless_rows();
  if (mopt_.attach) {  // an observer records across what it could not get (the run's monitor never does)
    l["missing_steps"] = rec_.missing_steps();
    l["gaps"] = nlohmann::ordered_json::array();
    for (const record::Gap& g : rec_.gaps())
      l["gaps"].push_back({{"first", g.first}, {"last", g.last}, {"why", g.why}});
  }
  l["steps_per_second"] = rec_.steps_per_second();
  l["bytes_per_step"] = bytes_per_step();
  l["safe_state"] = rec_.safe_state();
  l["stock_loggers"] = stock_loggers_json(sum, wall_time_s);
  add_latency_json(l, hists);
  return l;
}

nlohmann::ordered_json MonitorNode::command_conflict_json(const CommandConflict& c) {
  // The race of issue 19: which command the plant applied, and who sent each (UDP source).
  nlohmann::ordered_json j;
  j["step"] = c.step;
  j["first"] = {{"u", c.first.u}, {"sender", c.first.sender}};
  j["second"] = {{"u", c.second.u}, {"sender", c.second.sender}};
  if (c.applied_known) {
    const bool first = c.applied_first();
    j["applied"] = {
        {"u", c.applied_u}, {"sender", (first ? c.first : c.second).sender}, {"which", first ? "first" : "second"}};
  } else {
    j["applied"] = nullptr;
  }
  return j;
}

int MonitorNode::bytes_per_step() {
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
  return packet(channels().state, drive_state_t().getEncodedSize()) +
         packet(channels().reference, block.getEncodedSize()) / 16 +
         packet(channels().command, control_command_t().getEncodedSize());
}

nlohmann::ordered_json MonitorNode::stock_loggers_json(const sim::Summary& sum, double wall_time_s) const {
  // Stock loggers on the bus and whether the steps went out faster than the stock lcm-logger
  // records without loss (service::kStockLoggerSteps): the run cannot know what it dropped.
  const double run_rate = wall_time_s > 0 ? static_cast<double>(sum.steps) / wall_time_s : 0.0;
  const double peak = std::max(rate_.peak, run_rate);
  const bool too_fast =
      !rate_.loggers.empty() && peak > service::stock_logger_pace(rate_.loggers) * 1.02;  // 2 %: the window's clock
  nlohmann::ordered_json sl;
  sl["seen"] = nlohmann::ordered_json::array();
  for (const service::StockLogger& g : rate_.loggers) sl["seen"].push_back({{"name", g.name}, {"pid", g.pid}});
  sl["max_rate"] =
      options().max_rate > 0 ? nlohmann::ordered_json(options().max_rate) : nlohmann::ordered_json(nullptr);
  sl["peak_steps_per_second"] = peak;
  sl["records_without_loss_up_to"] = rate_.loggers.empty()
                                         ? nlohmann::ordered_json(nullptr)
                                         : nlohmann::ordered_json(service::stock_logger_pace(rate_.loggers));
  sl["faster_than_it_records"] = too_fast;
  if (too_fast)
    spdlog::warn(
        "{}: steps went out at up to {:.0f}/s while {} recorded the bus; it records without loss up to "
        "{:g}/s, so its log may miss steps (feeddrive-log2csv names them); pace the run with --max-rate {:g}",
        role(), peak, service::describe(rate_.loggers), service::stock_logger_pace(rate_.loggers),
        service::stock_logger_pace(rate_.loggers));
  return sl;
}

void MonitorNode::add_latency_json(nlohmann::ordered_json& l, const LatencyHistograms& hists) {
  const auto lat = [](const stats::StreamingQuantile& v, double q) { return v.quantile(q); };
  const auto hop = [&](const char* name, const stats::StreamingQuantile& v) {
    l["latency_us"][name] = {{"p50", lat(v, 0.5)}, {"p99", lat(v, 0.99)}, {"samples", v.count()}};
  };
  hop("state_to_command", rec_.latency_state_to_command());
  hop("command_to_state", rec_.latency_command_to_state());
  l["reference_lead_us"] = {{"p50", lat(rec_.reference_lead(), 0.5)},
                            {"p1", lat(rec_.reference_lead(), 0.01)},
                            {"samples", rec_.reference_lead().count()}};
  auto& h = l["latency_histogram_us"];
  h["bin_us"] = timing_.state_to_command.bin_us();
  for (std::size_t i = 0; i < hists.h.size(); ++i)
    h[hists.names[i]] = {
        {"counts", hists.h[i].counts()}, {"overflow", hists.h[i].overflow()}, {"samples", hists.h[i].samples()}};
  for (auto* v : {&l["latency_us"]["state_to_command"], &l["latency_us"]["command_to_state"], &l["reference_lead_us"]})
    for (const char* q : {"p50", "p99", "p1"})
      if (v->contains(q) && std::isnan((*v)[q].get<double>())) (*v)[q] = nullptr;
}

bool MonitorNode::write_results(const sim::Summary& sum, const std::string& write_error, const std::string& lockstep,
                                const LatencyHistograms& hists, bool& completed, std::string& why, std::string& where) {
  try {
    if (!write_error.empty()) throw std::runtime_error(write_error);
    const bool plots = mopt_.plots && out_->steps() > 0;
    // An incomplete record (interrupted, failed) never replaces an earlier output: it goes beside
    // it, to DIR.incomplete-N, and both are kept. An empty folder in DIR's place is no earlier
    // output: it is removed (rmdir removes only an empty one) and the record takes its place.
    const std::filesystem::path target = output::normalise(mopt_.out_dir);
    const bool earlier = output::is_feeddrive_output(target);
    if (!completed && !earlier) ::rmdir(target.c_str());
    const std::filesystem::path dest = out_->finish(
        sum, mopt_.plots, lockstep,
        [&](const output::StagedFolder& dir) { write_histograms(dir, hists.names, hists.h, plots); }, completed);
    if (!completed && dest != target) {
      where = dest.string();
      if (!options().quiet)  // an interrupt's one line stays one line with -q
        spdlog::info("monitor: the run did not complete; {} in {} is kept, this record is in {}",
                     earlier ? "the earlier output" : "what was already there", output::shown(mopt_.out_dir), where);
    }
    if (!out_->plot_error().empty() && !stop_.stop_requested())  // an interrupt is reported once, as such
      spdlog::warn("monitor: plots not drawn ({}); the data are in {}", out_->plot_error(), where);
    for (const std::string& w : out_->warnings()) spdlog::warn("monitor: {}", w);
    return true;
  } catch (const std::exception& e) {
    spdlog::error("monitor: writing {} failed: {}", output::shown(mopt_.out_dir), e.what());
    completed = false;
    if (why.empty()) why = std::string("results not written: ") + e.what();
    summary_.completed = false;
    summary_.failure = wire::fit(why, wire::Check<run_summary_t>::kMax_failure);
    return false;
  }
}

bool MonitorNode::finish(bool completed, const std::string& failure) {
  const double wall_time_s = static_cast<double>(mono_us() - when_.start) * 1e-6;
  sim::Summary sum;
  std::string write_error;  // the writer thread could not write (disk full, ...)
  try {
    sum = out_->summary(wall_time_s, {});
  } catch (const std::exception& e) {
    write_error = e.what();
  }
  const BusCounts counts = bus_counts();
  fill_summary(completed, failure, sum, wall_time_s, counts);
  const LatencyHistograms hists = latency_histograms();
  nlohmann::ordered_json j;
  j["lockstep"] = lockstep_json(completed, failure, sum, wall_time_s, counts, hists);

  std::string why = failure;
  std::string where = output::shown(mopt_.out_dir);
  const bool written = write_results(sum, write_error, j.dump(), hists, completed, why, where);
  bus().publish(channels().summary, summary_);
  if (completed) {
    set_state("done");
  } else {
    announce_failure(why);
  }
  if (!rec_.gaps().empty())
    spdlog::warn("{}: {}; the {} complete steps are in {}", role(), record::describe_gaps(rec_.gaps()), sum.steps,
                 where);
  if (!options().quiet)
    spdlog::info("monitor: {} steps recorded{} -> {}", sum.steps,
                 completed ? "" : " (stopped at step " + std::to_string(rec_.next()) + ": " + why + ")", where);
  return written;
}

void MonitorNode::write_histograms(const output::StagedFolder& dir, const std::vector<std::string>& names,
                                   const std::vector<Histogram>& h, bool plot) const {
  dir.write_text("latency_histogram.csv", histograms_csv(names, h));
  if (!plot || stop_.stop_requested()) return;  // interrupted while plotting: the data still go in place
  const double period_us = s_.control_period * 1e6;
  const std::string bin = std::to_string(h.front().bin_us());
  std::string gp =
      "set encoding utf8\nset datafile separator ','\nset terminal pngcairo size 1000,600 noenhanced\n"
      "set output 'latency_histogram.png'\nset grid\nset logscale y\nset yrange [0.5:*]\n"
      "set style fill transparent solid 0.4\nset boxwidth " +
      bin +
      "\n"
      "set xlabel 'latency [us] (bins of T/20 up to 2T; later ones in summary.json as overflow)'\n"
      "set ylabel 'steps'\nset title " +
      output::gnuplot_string(s_.name + (options().realtime ? " (real time)" : " (lockstep)")) + "\n";
  gp += "set arrow from " + std::to_string(period_us) + ",graph 0 to " + std::to_string(period_us) +
        ",graph 1 nohead dt 2\nset label 'T' at " + std::to_string(period_us) + ",graph 0.95\n";
  gp += "plot ";
  for (std::size_t i = 0; i < names.size(); ++i)
    gp += std::string(i ? ", " : "") + "'latency_histogram.csv' every ::1 using ($1+" +
          std::to_string(h.front().bin_us() / 2) + "):" + std::to_string(i + 2) + " with boxes title " +
          output::gnuplot_string(names[i]);
  gp += "\n";
  try {  // a view of the data: its failure (or an interrupt: the flag stays set) loses nothing
    output::run_gnuplot(dir.dir(), gp, stop_, "latency_histogram.gp");
  } catch (const std::runtime_error& e) {
    if (!stop_.stop_requested()) spdlog::warn("monitor: latency histogram not drawn ({})", e.what());
  }
}

}  // namespace feeddrive::monitor
