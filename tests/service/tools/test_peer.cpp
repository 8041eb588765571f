// fd-test-peer: misbehaving peers for the service tests, built on the same transport.
//   nan-controller  answers like a controller but sends NaN at steps k % 7 == 3 and 1e9 V at
//                   k % 7 == 5 (a plant must reject/clip and count them), 0.5 V otherwise
//   stall-controller answers with 0.5 V for the first --steps states, then goes silent
//   stale-controller answers with 0.5 V for the first --steps states, then answers state k with
//                   a new command carrying the stale step number k - 1
//   junk            publishes, every 1 ms for --seconds, a reference_block_t on <prefix>_CMD, a
//                   control_command_t on <prefix>_STATE and 7 random bytes on <prefix>_REF
//   forge-controller an attacker on the bus (issue 13): answers every new state k at once with its
//                   own control_command_t for step k, u = --u V, in the run's identity read off
//                   the states (no key: with --key on the run, its messages are unauthenticated)
//   forge-reference an attacker ahead of the trajectory: on every state k, a reference_block_t
//                   of position --u m for the aligned block 512 steps ahead (before the real one)
//   malformed       the datagrams that once killed every process of a run (issue 19), each in the
//                   run's identity, every 5 ms for --seconds: a process_status_t whose role has
//                   length 0, reference_block_t with count -1 and 10^7, a control_command_t and a
//                   drive_state_t with mac_size -1. Each must be counted invalid and dropped.
//   fake-monitor    a forged heartbeat of the run's monitor saying "running", every 10 ms for
//                   --seconds: after the real monitor's "done" it must not hold the run open.
//   fake-heartbeats forged heartbeats every 10 ms for --seconds (issue 19's review): the monitor
//                   "running" acknowledging step 10^9, the plant "running" at step 10^9, an
//                   attached monitor "running" whose acknowledgement moves each time. No one may
//                   end the run, stall the plant, or hold the linger open. (A plant heartbeat
//                   that goes back, without a key, is a restart: hil_test case 7b.)
//   replay-status   records the run's own heartbeats (signed, under --key) during its first
//                   0.3 s and sends them again, every 10 ms, until --seconds: the plant's go
//                   back; they must not end the run as a "restart".
//   mark            not a misbehaving peer: the flush markers of the tests that record with the
//                   stock lcm-logger (lib.sh, stop_logger). Every 20 ms for --seconds, the 5 bytes
//                   "flush" on <prefix>_TEST_FLUSH, a channel that is no part of the contract
//                   (docs/lcm-contract.md) and no LCM type: feeddrive-log2csv and feeddrive-fit
//                   count it among the foreign events. lcm-logger flushes its file only when an
//                   event comes (--flush-interval), so the markers bring its buffered tail out.
//   watch           not a misbehaving peer: only listens, and exits 0 once a state of step --steps
//                   or later is on <prefix>_STATE (the run is that far), 1 if none came within
//                   --seconds (lib.sh, wait_bus_step: a wait on the run's progress, not a sleep).
// Every peer joins the run of the first message it hears (or --run-id).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/process_status_t.hpp"
#include "feeddrive/reference_block_t.hpp"
#include "feeddrive/service/bus.hpp"

using namespace feeddrive;
using namespace feeddrive::service;

int main(int argc, char** argv) {
  CLI::App app{"fd-test-peer: misbehaving LCM peers for tests", "fd-test-peer"};
  std::string mode, url = default_lcm_url(), prefix = "FD";
  long steps = 100;
  double seconds = 1.0;
  double forged_u = 3.0;
  std::int64_t run_id = 0;
  app.add_option("mode", mode)
      ->required()
      ->check(CLI::IsMember({"nan-controller", "stall-controller", "junk", "stale-controller", "forge-controller",
                             "forge-reference", "malformed", "fake-monitor", "fake-heartbeats", "replay-status", "mark",
                             "watch"}));
  app.add_option("--u", forged_u, "forge-controller: the forged command [V]; forge-reference: the forged position [m]");
  app.add_option("--run-id", run_id, "the run to join (default: the first one heard)");
  app.add_option("--lcm-url", url);
  app.add_option("--prefix", prefix);
  app.add_option("--steps", steps);
  app.add_option("--seconds", seconds);
  CLI11_PARSE(app, argc, argv);

  if (mode == "mark") {
    lcm::LCM raw(url);
    if (!raw.good()) return 1;
    const std::string channel = prefix + "_TEST_FLUSH";
    const auto end = mono_us() + static_cast<std::int64_t>(seconds * 1e6);
    long n = 0;
    for (; mono_us() < end; ++n) {
      raw.publish(channel, "flush", 5);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));  // a rate, not a wait
    }
    std::printf("mark: %ld markers on %s\n", n, channel.c_str());
    return 0;
  }
  Bus bus(url);
  if (run_id != 0) {
    bus.set_run_id(run_id);
  } else {
    bus.join_first_seen();
  }
  const Channels ch(prefix);
  if (mode == "watch") {
    std::int64_t highest = -1;
    bus.subscribe<drive_state_t>(
        ch.state, [&](const drive_state_t& m, std::int64_t) { highest = std::max<std::int64_t>(highest, m.seq); });
    const auto end = mono_us() + static_cast<std::int64_t>(seconds * 1e6);
    while (highest < steps && mono_us() < end) bus.poll(std::chrono::milliseconds(10));
    std::printf("watch: highest state heard %lld (waited for %ld)\n", static_cast<long long>(highest), steps);
    return highest >= steps ? 0 : 1;
  }
  if (mode == "replay-status") {
    // The raw datagrams, as the run's processes signed them: a replay needs no key.
    lcm::LCM raw(url);
    if (!raw.good()) return 1;
    struct Capture {
      std::vector<std::vector<std::uint8_t>> kept;
      std::int64_t first_us{-1};
      void on(const lcm::ReceiveBuffer* rb, const std::string&) {
        const std::int64_t now = mono_us();
        if (first_us < 0) first_us = now;
        if (now - first_us < 300000 && kept.size() < 200)
          kept.emplace_back(static_cast<const std::uint8_t*>(rb->data),
                            static_cast<const std::uint8_t*>(rb->data) + rb->data_size);
      }
    } cap;
    raw.subscribe(ch.status, &Capture::on, &cap);
    const auto give_up = mono_us() + 60000000;
    while ((cap.first_us < 0 || mono_us() - cap.first_us < 300000) && mono_us() < give_up) raw.handleTimeout(10);
    if (cap.kept.empty()) {
      std::printf("%s: heard no heartbeat\n", mode.c_str());
      return 1;
    }
    std::printf("%s: replaying %zu heartbeats of the run's first 0.3 s\n", mode.c_str(), cap.kept.size());
    std::fflush(stdout);
    const auto end = mono_us() + static_cast<std::int64_t>(seconds * 1e6);
    long n = 0;
    // Every 10 ms, on a clock: handleTimeout returns at the next message, and the run sends
    // thousands a second, so a loop paced by it re-sent the 200 heartbeats per message heard
    // (hundreds of thousands a second), a flood that starved a loaded monitor (its
    // acknowledgements stopped) rather than the replay the test is about.
    std::int64_t next = mono_us();
    while (mono_us() < end) {
      for (const auto& b : cap.kept) raw.publish(ch.status, b.data(), static_cast<unsigned>(b.size()));
      ++n;
      next += 10000;
      for (std::int64_t now = mono_us(); now < next; now = mono_us())
        raw.handleTimeout(static_cast<int>(std::max<std::int64_t>(1, (next - now) / 1000)));
    }
    std::printf("%s: replayed %zu heartbeats %ld times\n", mode.c_str(), cap.kept.size(), n);
    return 0;
  }
  if (mode == "malformed" || mode == "fake-monitor" || mode == "fake-heartbeats") {
    bus.subscribe<drive_state_t>(ch.state, [](const drive_state_t&, std::int64_t) {});
    const auto give_up = mono_us() + 60000000;
    while (!bus.run_known() && mono_us() < give_up) bus.poll(std::chrono::milliseconds(10));
    if (!bus.run_known()) {
      std::printf("%s: heard no run\n", mode.c_str());
      return 1;
    }
    const std::int64_t run = bus.run_id();
    // be(b, at, v, n): v big-endian into n bytes at `at` (LCM's byte order).
    const auto be = [](std::vector<std::uint8_t>& b, std::size_t at, std::int64_t v, std::size_t n) {
      for (std::size_t i = 0; i < n; ++i)
        b[at + i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(v) >> (8 * (n - 1 - i)));
    };
    const auto bytes = [](const auto& m) {
      std::vector<std::uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
      m.encode(b.data(), 0, static_cast<int>(b.size()));
      return b;
    };
    process_status_t st{};
    st.run_id = run;
    st.role = mode == "fake-monitor" ? "monitor" : "plant";
    st.state = "running";
    std::vector<std::vector<std::uint8_t>> status_bad, ref_bad, cmd_bad, state_bad;
    if (mode == "malformed") {
      auto b = bytes(st);
      // The role's length field: the big-endian 6 right before "plant" and its NUL.
      for (std::size_t i = 8; i + 10 <= b.size(); ++i)
        if (b[i] == 0 && b[i + 1] == 0 && b[i + 2] == 0 && b[i + 3] == 6 && std::memcmp(&b[i + 4], "plant", 6) == 0) {
          be(b, i, 0, 4);
          break;
        }
      status_bad.push_back(b);
      reference_block_t rb{};
      rb.run_id = run;
      rb.count = 1;
      rb.refs.resize(1);
      b = bytes(rb);
      be(b, 24, -1, 4);  // fingerprint, run_id, first_seq, then count
      ref_bad.push_back(b);
      be(b, 24, 10000000, 4);
      ref_bad.push_back(b);
      control_command_t c{};
      c.run_id = run;
      b = bytes(c);
      be(b, b.size() - 2, -1, 2);  // mac_size is the last field (no mac)
      cmd_bad.push_back(b);
      drive_state_t d{};
      d.run_id = run;
      b = bytes(d);
      be(b, b.size() - 2, -1, 2);
      state_bad.push_back(b);
    }
    const auto end = mono_us() + static_cast<std::int64_t>(seconds * 1e6);
    long n = 0;
    while (mono_us() < end) {
      if (mode == "fake-monitor") {
        st.utime = wall_utime();
        bus.publish(ch.status, st);
      } else if (mode == "fake-heartbeats") {
        process_status_t f = st;
        f.utime = wall_utime();
        f.role = "monitor";
        f.acked_seq = 1000000000;
        bus.publish(ch.status, f);
        f.role = "plant";
        f.seq = 1000000000;
        f.acked_seq = 0;
        bus.publish(ch.status, f);
        f.role = "monitor-attached";
        f.seq = 0;
        f.acked_seq = n;
        bus.publish(ch.status, f);
      } else {
        for (const auto& b : status_bad) bus.publish_raw(ch.status, b.data(), b.size());
        for (const auto& b : ref_bad) bus.publish_raw(ch.reference, b.data(), b.size());
        for (const auto& b : cmd_bad) bus.publish_raw(ch.command, b.data(), b.size());
        for (const auto& b : state_bad) bus.publish_raw(ch.state, b.data(), b.size());
      }
      ++n;
      // Paced by the clock, not by what it hears (a poll returns at the first datagram, and the
      // run sends tens of thousands a second): this peer forges, it does not flood.
      const auto tick = mono_us() + (mode == "malformed" ? 5000 : 10000);
      for (std::int64_t now = mono_us(); now < tick; now = mono_us()) bus.poll(std::chrono::microseconds(tick - now));
    }
    std::printf("%s: %ld rounds in run %lld\n", mode.c_str(), n, static_cast<long long>(run));
    return 0;
  }
  if (mode == "junk") {
    lcm::LCM raw(url);
    std::mt19937 rng(7);
    const auto end = mono_us() + static_cast<std::int64_t>(seconds * 1e6);
    long n = 0;
    while (mono_us() < end) {
      reference_block_t r{};
      r.count = 1;
      r.refs.resize(1);
      bus.publish(ch.command, r);
      control_command_t c{};
      bus.publish(ch.state, c);
      unsigned char bytes[7];
      for (auto& b : bytes) b = static_cast<unsigned char>(rng());
      raw.publish(ch.reference, bytes, sizeof bytes);
      ++n;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    std::printf("junk: %ld rounds\n", n);
    return 0;
  }
  if (mode == "forge-controller" || mode == "forge-reference") {
    std::int64_t highest = -1, forged = 0;
    bool end = false;
    std::int64_t last_us = mono_us();
    bus.subscribe<drive_state_t>(ch.state, [&](const drive_state_t& m, std::int64_t now) {
      if (m.end_of_run) end = true;
      last_us = now;
      if (m.end_of_run || m.seq <= highest) return;
      highest = m.seq;
      if (mode == "forge-controller") {
        control_command_t c{};
        c.seq = m.seq;
        c.t = m.t;
        c.u = c.u_unsaturated = forged_u;
        c.sliding = c.z_estimate = std::nan("");
        bus.publish(ch.command, c);
        ++forged;
      } else if (m.seq % 16 == 0 && m.seq + 512 < m.steps) {
        reference_block_t b{};
        b.first_seq = m.seq + 512;
        b.count = 16;
        for (std::int64_t k = b.first_seq; k < b.first_seq + 16; ++k) {
          reference_t r{};
          r.seq = k;
          r.t = m.t + static_cast<double>(k - m.seq) * (m.seq > 0 ? m.t / static_cast<double>(m.seq) : 0.0);
          r.position = forged_u;
          b.refs.push_back(r);
        }
        bus.publish(ch.reference, b);
        ++forged;
      }
    });
    while (!end && mono_us() - last_us < 10'000'000) bus.poll(std::chrono::milliseconds(10));
    std::printf("%s: %lld forged messages\n", mode.c_str(), static_cast<long long>(forged));
    return 0;
  }
  std::map<std::int64_t, control_command_t> answered;
  bool end = false;
  std::int64_t last_us = mono_us();
  bus.subscribe<drive_state_t>(ch.state, [&](const drive_state_t& m, std::int64_t now) {
    if (m.end_of_run) {
      end = true;
      return;
    }
    last_us = now;
    if (mode == "stall-controller" && m.seq >= steps) return;
    if (mode == "stale-controller" && m.seq >= steps) {
      control_command_t c{};
      c.seq = m.seq - 1;
      c.t = m.t;
      c.u = c.u_unsaturated = 0.5 + 1e-3 * static_cast<double>(m.seq);  // not the command applied for k - 1
      c.sliding = c.z_estimate = std::nan("");
      bus.publish(ch.command, c);
      return;
    }
    auto it = answered.find(m.seq);
    if (it == answered.end()) {
      control_command_t c{};
      c.seq = m.seq;
      c.t = m.t;
      c.u = 0.5;
      if (mode == "nan-controller" && m.seq % 7 == 3) c.u = std::nan("");
      if (mode == "nan-controller" && m.seq % 7 == 5) c.u = 1e9;
      c.u_unsaturated = c.u;
      c.sliding = c.z_estimate = std::nan("");
      it = answered.emplace(m.seq, c).first;
    }
    bus.publish(ch.command, it->second);
  });
  while (!end && mono_us() - last_us < 10'000'000) bus.poll(std::chrono::milliseconds(10));
  std::printf("%s: %zu steps answered\n", mode.c_str(), answered.size());
  return 0;
}
