// lcm-pingpong: the ceiling of a lockstep step on this machine. Two processes, the same
// transport and message types as a lockstep step: the client publishes a drive_state_t on
// <prefix>_PING, the server answers each with a control_command_t on <prefix>_PONG, and the
// client sends the next ping when the pong arrives. One round trip per "step", like the
// plant <-> controller exchange.
//   lcm-pingpong server [--lcm-url URL] [--prefix P]
//   lcm-pingpong client --count N [--lcm-url URL] [--prefix P]   -> prints "pingpong_rate <per s>"
//   lcm-pingpong listen [--batched] --seconds S [--lcm-url URL]  -> sits on the group for S seconds,
//       subscribed to a channel nobody publishes: what another process on the group costs the
//       ping-pong, with liblcm's receive or with the batched one (service/udpm_reader.hpp).
#include <CLI/CLI.hpp>

#include <cstdio>

#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/service/bus.hpp"

using namespace feeddrive;
using namespace feeddrive::service;

int main(int argc, char** argv) {
  CLI::App app{"lcm-pingpong: raw LCM round trips between two processes", "lcm-pingpong"};
  std::string mode, url = default_lcm_url(), prefix = "PP";
  long count = 20000;
  double seconds = 10.0;
  bool batched = false, liblcm = false;
  app.add_option("mode", mode)->required()->check(CLI::IsMember({"server", "client", "listen"}));
  app.add_option("--seconds", seconds, "listen: how long");
  app.add_flag("--batched", batched, "listen: read the group in batches instead of with liblcm's receive thread");
  app.add_flag("--liblcm", liblcm,
               "server/client: receive with liblcm's receive thread (Receive::kEvent) instead of the direct socket");
  app.add_option("--lcm-url", url);
  app.add_option("--prefix", prefix);
  app.add_option("--count", count);
  CLI11_PARSE(app, argc, argv);
  // listen: liblcm's receive (what a stock LCM process on the group costs) or the batched one;
  // server/client: the project's Bus as the plant and the controller use it (kDirect).
  const Receive receive = mode == "listen" ? (batched ? Receive::kBatched : Receive::kEvent)
                                           : (liblcm ? Receive::kEvent : Receive::kDirect);
  Bus bus(url, receive);
  bus.set_run_id(1);  // both ends of the ping-pong are one "run" (Admit::kRun drops messages until it is known)
  if (mode == "listen") {
    bus.subscribe<control_command_t>(prefix + "_NOBODY", [](const control_command_t&, std::int64_t) {});
    const std::int64_t end = mono_us() + static_cast<std::int64_t>(seconds * 1e6);
    while (mono_us() < end) bus.poll(std::chrono::milliseconds(100));
    return 0;
  }
  const std::string ping = prefix + "_PING", pong = prefix + "_PONG";
  if (mode == "server") {
    bool stop = false;
    std::int64_t last = mono_us();
    bus.subscribe<drive_state_t>(ping, [&](const drive_state_t& m, std::int64_t now) {
      last = now;
      control_command_t c{};
      c.seq = m.seq;
      c.t = m.t;
      bus.publish(pong, c);
      if (m.end_of_run) stop = true;
    });
    while (!stop && mono_us() - last < 30'000'000) bus.poll(std::chrono::milliseconds(100));
    return 0;
  }
  std::int64_t answered = -2;
  bus.subscribe<control_command_t>(pong, [&](const control_command_t& c, std::int64_t) {
    if (c.seq > answered) answered = c.seq;
  });
  drive_state_t s{};
  s.truth.valid = true;
  s.previous.seq = -1;
  // Warm up until the server answers (it may start later), then time `count` round trips.
  s.seq = -1;
  const std::int64_t start_wait = mono_us();
  while (answered < -1) {
    if (mono_us() - start_wait > 30'000'000) {
      std::fprintf(stderr, "error: no pong from the server within 30 s\n");
      return 1;
    }
    bus.publish(ping, s);
    bus.poll(std::chrono::milliseconds(10));
  }
  const std::int64_t t0 = mono_us();
  for (std::int64_t k = 0; k < count; ++k) {
    s.seq = k;
    bus.publish(ping, s);
    std::int64_t sent = mono_us();
    while (answered < k) {
      bus.poll(std::chrono::microseconds(2000));
      if (answered < k && mono_us() - sent > 2000) {  // lost: send again
        bus.publish(ping, s);
        sent = mono_us();
      }
    }
  }
  const double dt = static_cast<double>(mono_us() - t0) * 1e-6;
  s.end_of_run = true;
  for (int i = 0; i < 3; ++i) bus.publish(ping, s);
  std::printf("pingpong_rate %.1f\n", static_cast<double>(count) / dt);
  return 0;
}
