#pragma once
// The in-process protocol tests (issue 22, point 6): one node under test and scripted peers
// (service::Bus instances playing the other roles) on one LCM memq:// instance, so that the
// lockstep protocol is exercised without multicast. memq:// delivers a message to every
// subscription of the instance it was published on, in publication order, when some bus on it
// calls handle() (Bus::poll). So the whole exchange runs on the test's thread: the node's
// run() polls, and each peer's handler answers inside that poll by publishing again.
// A peer's handler must not throw (the node's poll would keep its exception for the peer's own
// poll, which may never come): it records what it saw, the test asserts afterwards.
#include <gtest/gtest.h>
#include <lcm/lcm.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "feeddrive/record/channels.hpp"
#include "feeddrive/service/bus.hpp"
#include "feeddrive/service/node.hpp"
#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::protocol_test {

using namespace std::chrono_literals;

/// One memq:// instance, opened first and closed last: every Bus on it is gone by then
/// (declare it before the node and the peers).
struct Memq {
  lcm_t* lcm = lcm_create("memq://");
  Memq() { EXPECT_NE(lcm, nullptr) << "lcm_create(memq://) failed"; }
  ~Memq() { lcm_destroy(lcm); }
  Memq(const Memq&) = delete;
  Memq& operator=(const Memq&) = delete;
};

/// The run id every test's messages carry.
inline constexpr std::int64_t kRunId = 7;

/// Options for a node on memq://. Timeouts of 30 s: only a test that is about a timeout sets a
/// short one, so a loaded machine cannot fail the others.
inline service::NodeOptions node_options() {
  service::NodeOptions o;
  o.lcm_url = "memq://";
  o.run_id = kRunId;
  o.quiet = true;
  o.start_timeout_s = 30.0;
  o.step_timeout_s = 30.0;
  o.resend_interval_s = 0.002;
  o.monitor_window = 0;  // the plant's flow control only where a test is about it
  o.linger_s = 0.0;      // no monitor to wait for after the end
  return o;
}

/// A peer: a bus on the shared instance, in the run.
inline std::unique_ptr<service::Bus> peer(const Memq& m, std::int64_t run_id = kRunId) {
  auto b = std::make_unique<service::Bus>("memq://", service::Receive::kEvent, m.lcm);
  b->set_run_id(run_id);
  return b;
}

/// Polls `bus` until done() or `deadline` has passed; returns done(). The wait on a condition
/// with a deadline that these tests use instead of a fixed sleep.
inline bool poll_until(service::Bus& bus, const std::function<bool()>& done,
                       std::chrono::milliseconds deadline = 5000ms) {
  const std::int64_t until = service::mono_us() + deadline.count() * 1000;
  while (!done()) {
    if (service::mono_us() > until) return false;
    bus.poll(std::chrono::milliseconds(10));
  }
  return true;
}

/// The service tests' short jerk-limited move (tests/service/scenarios/short_jerk.yaml), cut to
/// `steps` steps of T = 0.1 ms.
inline sim::Scenario scenario(long steps) {
  return sim::parse_scenario("name: protocol\nduration: " + std::to_string(static_cast<double>(steps) * 1e-4) +
                             "\ncontrol_period: 1e-4\nplant:\n  friction: {model: lugre}\n"
                             "controller:\n  type: sliding_mode\n  switching: sat\n  boundary_layer: 5.0e-4\n"
                             "reference:\n  type: scurve\n  distance: 0.1\n  max_velocity: 0.2\n"
                             "  max_acceleration: 1.15\n  max_jerk: 2.4\n");
}

/// The channels of the tests' runs (prefix FD).
inline const record::Channels kCh("FD");

/// The command for step k in the scripted runs [V]: within the input limit, different for every
/// step, so a command applied at the wrong step shows.
inline double u_of(std::int64_t k) { return 0.5 + 0.01 * static_cast<double>(k); }

/// Runs `f` (a node's run()) and returns its RunFailure's one line ("" if it returned).
template <typename F>
std::string failure_of(F&& f) {
  try {
    f();
  } catch (const service::RunFailure& e) {
    return e.what();
  }
  return "";
}

/// Checks that `failure` names a conflict on `channel` at `step` between two `type` messages
/// whose `fields` differ, as Node::admit says it.
inline void expect_conflict(const std::string& failure, const std::string& channel, std::int64_t step,
                            const std::string& type, const std::string& fields) {
  const std::string line = "conflict on " + channel + " step " + std::to_string(step) + ": two different " + type +
                           " for one step (" + fields + " differ)";
  EXPECT_NE(failure.find(line), std::string::npos) << failure;
}

/// Runs `run` (returns the run's failure line) and checks the failure starts with `expected` and
/// came no earlier than the timeout `limit_s` (the protocol never gives up early) and no later
/// than 10 s after it (a hang; generous for a loaded machine).
template <typename F>
void expect_failure_after(double limit_s, const std::string& expected, F&& run) {
  const std::int64_t start = service::mono_us();
  const std::string failure = run();
  const double took = static_cast<double>(service::mono_us() - start) * 1e-6;
  EXPECT_EQ(failure.substr(0, expected.size()), expected) << failure;
  EXPECT_GE(took, limit_s);
  EXPECT_LT(took, limit_s + 10.0);
}

}  // namespace feeddrive::protocol_test
