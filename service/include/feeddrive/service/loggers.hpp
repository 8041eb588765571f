#pragma once
// Stock LCM loggers on a run's bus, and the pace at which the stock lcm-logger records without
// loss (docs/lcm-contract.md, "Recording with the stock lcm-logger").
//
// liblcm's lcm-logger reads the group in a receive thread that queues each message for its main
// thread, at most 30 per subscription (LCM's default queue, not configurable in the stock tool);
// the 31st is dropped silently. Nothing can resend what only the logger missed, so a run the
// logger must keep up with is paced: at `kStockLoggerSteps` steps per second at most (about 2.2
// datagrams a step: state, command, 1/16 of a reference block, heartbeats), the logger may be
// kept off a CPU for 30 / (2.2 * rate) seconds (13 ms at 1,000 steps/s) before its queue is full.

#include <string>
#include <vector>

namespace feeddrive::service {

/// Steps per second the stock lcm-logger records without loss on the development VM with both
/// cores under a concurrent CPU load (stress-ng --cpu 2), measured with bench/logger_pace_bench.sh
/// (docs/lcm-contract.md has the figures): at real-time priority (chrt -f 20), 1000 (20 of 20
/// runs complete); at normal priority the scheduler may keep it off a CPU for longer than its
/// queue lasts at 1000 (2 of 7 runs lost 2-3 steps), so a logger at normal priority gets
/// kStockLoggerStepsNormal.
inline constexpr double kStockLoggerSteps = 1000.0;
inline constexpr double kStockLoggerStepsNormal = 500.0;

/// A process of a known stock logger ("lcm-logger") with a UDP socket bound to the port of
/// `lcm_url` in this network namespace (it hears the run's group).
struct StockLogger {
  int pid{0};
  std::string name;
  bool realtime{false};  ///< scheduled SCHED_FIFO or SCHED_RR
};

/// The pace at which all of `loggers` record without loss: kStockLoggerSteps when each runs at
/// real-time priority, else kStockLoggerStepsNormal.
double stock_logger_pace(const std::vector<StockLogger>& loggers);

/// The stock loggers on the bus of `lcm_url` (udpm:// only; other URLs: none), found through
/// /proc (net/udp for the port's sockets, fd/ for their owners). Never throws: a /proc that cannot
/// be read gives none.
std::vector<StockLogger> stock_loggers_on(const std::string& lcm_url);

/// The local process that owns the UDP socket bound to `port` in this network namespace, as
/// "NAME (pid N)", found through /proc as stock_loggers_on does; "" when none is (a sender on
/// another machine) or /proc cannot say. Names the sender of a message by its UDP source port.
std::string local_process_on_udp_port(int port);

/// "lcm-logger (pid 123), lcm-logger (pid 456)".
std::string describe(const std::vector<StockLogger>& loggers);

}  // namespace feeddrive::service
