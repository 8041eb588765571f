#pragma once
// LCM transport of the multi-process service: one LCM instance, typed subscriptions that count
// and drop undecodable messages (wrong type or fingerprint) instead of crashing, and publishers
// that keep their recent messages so a lost one can be re-published on request.
//
// Three ways to receive: kDirect (udpm_reader.hpp's socket, waited on directly: woken once by
// each datagram, for the step's critical path, the plant and the controller), kBatched (the same
// socket, but sleep for a batch interval, then take everything queued, for the monitor and the
// trajectory) and kEvent (liblcm's receive thread and its notification pipe: two wake-ups per
// message; the fallback for URLs other than udpm://, e.g. memq://). All publish with liblcm,
// and all see the same messages: the choice changes when a process wakes, not what it gets.
//
// Nothing here knows about drives: the nodes (plant_node.hpp, ...) hold the protocol logic.

#include <spdlog/spdlog.h>
#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "feeddrive/record/channels.hpp"
#include "feeddrive/service/integrity.hpp"
#include "feeddrive/service/udpm_reader.hpp"
#include "feeddrive/wire.hpp"

namespace feeddrive::service {

/// LCM URL used when none is given: multicast on the LCM default group with ttl = 0 (nothing
/// leaves the machine) and a 4 MB receive buffer (LCM's default is the kernel's, which drops
/// under bursts).
std::string default_lcm_url();

/// The channel names of one run (feeddrive/record/channels.hpp: no transport needed to name them).
using record::Channels;

/// Microseconds since the Unix epoch (process_status_t.utime) and a monotonic clock [us].
std::int64_t wall_utime();
std::int64_t mono_us();

/// Which runs' messages a subscription gets (see Bus::set_run_id).
enum class Admit {
  kRun,     ///< only the bus's run: others are counted as foreign and dropped (all message flow)
  kAnyRun,  ///< every run's (the heartbeat, from which a process joins a run); the handler checks
};

enum class Receive {
  kDirect,   ///< our socket, woken by each datagram: lowest latency (udpm:// URLs; else kEvent)
  kBatched,  ///< drained every batch interval, no wake-up per message (udpm:// URLs; else kEvent)
  kEvent,    ///< liblcm's receive thread: two wake-ups per message (receive thread, then pipe)
};

/// What a bus drops, for a process that names the sender (the monitor: contract.hpp). Each
/// is called for every such message, after it is counted.
struct BusEvents {
  /// With a key: a message without a valid mac (channel, its bytes).
  std::function<void(const std::string&, const std::uint8_t*, std::size_t)> unauthenticated;
  /// A message that does not decode as its channel's type or breaks the contract's bounds
  /// (channel, its bytes, why: "reference_block_t.count = -1 (bound 1..16)").
  std::function<void(const std::string&, const std::uint8_t*, std::size_t, const std::string&)> undecodable;
  /// A message of another run (channel, its run id, the sender's role if known, else "").
  std::function<void(const std::string&, std::int64_t, const std::string&)> foreign;
};

class Bus {
 public:
  /// Throws std::runtime_error naming the URL when LCM cannot be initialised. kDirect and
  /// kBatched fall back to kEvent for URLs other than udpm:// (memq://, file://).
  /// `shared`: instead of opening `url`, publish and receive through this liblcm instance, which
  /// the caller opened, owns and keeps until the bus is gone (kEvent). Several buses on one
  /// memq:// instance hear each other in one process: the protocol tests (tests/protocol).
  explicit Bus(const std::string& url, Receive receive = Receive::kDirect, lcm_t* shared = nullptr);
  ~Bus();
  /// kBatched: how long poll() sleeps before it takes what is queued.
  static constexpr std::chrono::microseconds kBatchInterval{1000};
  Bus(const Bus&) = delete;
  Bus& operator=(const Bus&) = delete;

  /// Subscribes to `channel`, decoding every message as Msg. With a key (set_auth), a message
  /// without a valid mac is counted in unauthenticated() and dropped before it is decoded.
  /// Messages that fail to decode (another type, another fingerprint, truncated) are counted in
  /// invalid() and dropped. Admit::kRun: a message of another run is counted in foreign() and
  /// dropped, and before the run is known (run_known()) every message is dropped uncounted.
  /// recv_us is the monotonic time [us] at which LCM received the datagram.
  template <typename Msg>
  void subscribe(const std::string& channel, std::function<void(const Msg&, std::int64_t recv_us)> handler,
                 Admit admit = Admit::kRun);

  /// Publishes a message stamped with the run's identity (run_id), signed when a key is set.
  /// Returns false (and counts) when LCM reports a send error.
  template <typename Msg>
  bool publish(const std::string& channel, const Msg& msg);

  /// Publishes bytes as they are (no stamp, no mac): a recorded message replayed, or a test's
  /// malformed datagram. Returns false (and counts) when LCM reports a send error.
  bool publish_raw(const std::string& channel, const std::uint8_t* data, std::size_t size);

  /// The run this bus belongs to. Until it is set, Admit::kRun subscriptions get nothing.
  void set_run_id(std::int64_t id) {
    run_id_ = id;
    run_known_ = true;
  }
  bool run_known() const { return run_known_; }
  /// Until the run is known, join the run of the first message that arrives on an Admit::kRun
  /// subscription (an attached recorder: whatever is on the bus, a replayed log too).
  void join_first_seen() { join_first_ = true; }
  std::int64_t run_id() const { return run_id_; }
  /// Authenticates every message with this key from now on (integrity.hpp).
  void set_auth(const std::string& key) { auth_ = std::make_unique<MessageAuth>(key); }
  bool authenticated() const { return auth_ != nullptr; }
  /// Counts (and logs, at most once a second) a message of another run seen by an
  /// Admit::kAnyRun handler.
  void count_foreign(const std::string& channel, std::int64_t run_id, const std::string& role = "");
  /// Names the senders of what it drops (events) instead of the bus's own lines.
  void set_events(BusEvents e) { events_ = std::move(e); }
  /// false: the bus only counts foreign, unauthenticated and undecodable messages, it logs no
  /// line (under feeddrive-launch one process, the monitor, names them: one line per event).
  void set_reports(bool on) { reports_ = on; }

  /// Dispatches the messages that arrive within `timeout` (at least one wait). Returns true if
  /// at least one message was handled. Rethrows the first exception a handler threw.
  /// kBatched: sleeps min(timeout, batch interval), then dispatches everything queued.
  /// kDirect: waits on the socket until a datagram comes (or the timeout), then dispatches
  /// everything queued.
  bool poll(std::chrono::microseconds timeout);
  bool batched() const { return reader_ != nullptr && receive_ == Receive::kBatched; }

  /// Called with every complete LCM message this bus receives (kDirect and kBatched), before
  /// it is dispatched, whatever its channel: a recorder's tap (the monitor's --lcm-log).
  void set_tap(MessageSink tap) { tap_ = std::move(tap); }

  /// Messages that did not decode as their channel's type or broke the contract's bounds, and
  /// datagrams that are not LCM's framing (kDirect, kBatched).
  std::int64_t invalid() const { return invalid_ + (reader_ ? reader_->malformed() : 0); }
  /// invalid() by channel; datagrams without LCM's framing (no channel) under "" .
  std::map<std::string, std::int64_t> invalid_by_channel() const;
  /// Counts (and logs, at most once a second) a message of `channel` that did not decode.
  void count_invalid(const std::string& channel, const std::uint8_t* data, std::size_t size, const std::string& why);
  /// Messages of another run (Admit::kRun subscriptions, and count_foreign()).
  std::int64_t foreign() const { return foreign_; }
  /// Publish calls that failed (each logged, at most once a second); read at the end of a run
  /// (~Node reports a non-zero count).
  std::int64_t send_errors() const { return send_errors_; }
  /// With a key: messages without a valid mac.
  std::int64_t unauthenticated() const { return unauthenticated_; }
  const std::string& url() const { return url_; }
  /// Inside a handler: who sent the message being handled, "IP:PORT" of its UDP source (kDirect,
  /// kBatched), or "" (kEvent: liblcm does not say).
  std::string current_source() const { return reader_ ? reader_->current_source() : std::string(); }
  /// Inside a handler (and the foreign/invalid events it raises): when the message being handled
  /// was received, on the monotonic clock [us]: the kernel's time, not the dispatch's, so that a
  /// process reading a backlog judges "silent since" on the time line the messages came in.
  std::int64_t current_recv_us() const { return current_recv_us_; }

 private:
  struct Raw {
    std::function<void(const lcm::ReceiveBuffer*, const std::string&)> f;
    void handle(const lcm::ReceiveBuffer* rbuf, const std::string& channel) { f(rbuf, channel); }
  };
  void subscribe_raw(const std::string& channel, std::function<void(const lcm::ReceiveBuffer*, const std::string&)> f);
  bool poll_event(std::chrono::microseconds timeout);
  bool poll_batched(std::chrono::microseconds timeout);
  bool poll_direct(std::chrono::microseconds timeout);
  std::size_t drain();
  void rethrow_handler_error();

  std::int64_t current_recv_us_{0};
  std::string url_;
  bool shared_;  ///< lcm_ wraps the caller's instance: ~Bus() takes its subscriptions off it
  lcm::LCM lcm_;
  std::vector<std::unique_ptr<Raw>> raws_;
  std::vector<lcm::Subscription*> subscriptions_;  ///< liblcm's (kEvent)
  Receive receive_;
  std::unique_ptr<UdpmReader> reader_;  ///< kDirect and kBatched on udpm:// URLs
  MessageSink tap_;
  std::unordered_map<std::string, std::vector<Raw*>> batched_subs_;
  std::int64_t invalid_{0};
  std::map<std::string, std::int64_t> invalid_by_channel_;
  std::int64_t send_errors_{0};
  std::int64_t last_send_error_log_us_{-1};
  std::int64_t last_invalid_log_us_{-1};
  std::int64_t foreign_{0};
  std::int64_t last_foreign_log_us_{-1};
  std::int64_t unauthenticated_{0};
  std::int64_t last_unauthenticated_log_us_{-1};
  std::int64_t run_id_{0};
  bool run_known_{false};
  bool join_first_{false};
  std::unique_ptr<MessageAuth> auth_;
  BusEvents events_;
  bool reports_{true};
  std::vector<std::uint8_t> out_;  ///< publish(): the encoded message
  std::exception_ptr error_;
  /// Logs at most once a second per kind: `last` is that kind's last log time.
  static bool log_due(std::int64_t& last);
  /// liblcm's publish result `rc` on `channel`: 0 is true; a failure (the socket's buffer full,
  /// no route) is counted and logged, at most once a second, and false.
  bool sent(int rc, const std::string& channel);
};

/// Remembers the last `capacity` messages published on one channel, by step number, and
/// re-publishes one on request, if it was not re-published within `min_interval_us`.
template <typename Msg>
class Outbox {
 public:
  Outbox(Bus& bus, std::string channel, std::size_t capacity = 65536)
      : bus_(bus), channel_(std::move(channel)), capacity_(capacity) {}
  void publish(std::int64_t seq, const Msg& msg) {
    // No clock read here: publish() is on every step's path; only re-publications are timed.
    auto [it, inserted] = sent_.insert_or_assign(seq, Sent{msg, kNever});
    (void)it;
    if (inserted) order_.push_back(seq);
    while (order_.size() > capacity_) {
      sent_.erase(order_.front());
      order_.pop_front();
    }
    bus_.publish(channel_, msg);
  }
  /// Re-publishes message `seq` if it is still kept and was not re-published within the last
  /// `min_interval_us` (several requesters asking within one resend interval get one copy);
  /// returns whether it was re-published.
  bool republish(std::int64_t seq, std::int64_t min_interval_us = 0) {
    const auto it = sent_.find(seq);
    if (it == sent_.end()) return false;
    const std::int64_t now = mono_us();
    if (it->second.resent_us != kNever && now - it->second.resent_us < min_interval_us) return false;
    bus_.publish(channel_, it->second.msg);
    it->second.resent_us = now;
    ++resends_;
    return true;
  }
  bool has(std::int64_t seq) const { return sent_.count(seq) != 0; }
  const std::string& channel() const { return channel_; }
  std::int64_t resends() const { return resends_; }

 private:
  Bus& bus_;
  std::string channel_;
  std::size_t capacity_;
  static constexpr std::int64_t kNever = -1;
  struct Sent {
    Msg msg;
    std::int64_t resent_us;  ///< when it was last re-published (mono_us), or kNever
  };
  std::map<std::int64_t, Sent> sent_;
  std::deque<std::int64_t> order_;
  std::int64_t resends_{0};
};

// --- template definitions -------------------------------------------------------------------

template <typename Msg>
void Bus::subscribe(const std::string& channel, std::function<void(const Msg&, std::int64_t)> handler, Admit admit) {
  subscribe_raw(channel, [this, handler, admit](const lcm::ReceiveBuffer* rbuf, const std::string& ch) {
    const auto* bytes = static_cast<const std::uint8_t*>(rbuf->data);
    if (auth_ && !auth_->verify(ch, bytes, rbuf->data_size)) {
      ++unauthenticated_;
      if (events_.unauthenticated) events_.unauthenticated(ch, bytes, rbuf->data_size);
      else if (reports_ && log_due(last_unauthenticated_log_us_))
        spdlog::warn("rejected a message on {} without a valid mac ({} so far; forged, or a publisher without the key)",
                     ch, unauthenticated_);
      return;
    }
    // Every received byte is untrusted: decode_untrusted walks the encoding against the
    // contract's bounds before anything is allocated and never throws (lcmtypes/.../wire.hpp).
    Msg msg;
    const std::int64_t now = mono_us();
    std::string why;
    if (!wire::decode_untrusted(rbuf->data, rbuf->data_size, msg, &why)) {
      count_invalid(ch, bytes, rbuf->data_size, why);
      return;
    }
    // The receive time is when LCM read the datagram off the socket (recv_utime: the kernel's
    // SO_TIMESTAMP where available, else LCM's clock on reading), not when handle() dispatches
    // it: a process that drains its socket in batches (the monitor) would otherwise stamp a
    // whole batch with one time, and the latency per hop would measure nothing. recv_utime is
    // wall-clock; its age moves it onto the monotonic clock.
    std::int64_t recv = now;
    if (rbuf->recv_utime > 0) {
      const std::int64_t age = wall_utime() - rbuf->recv_utime;
      if (age > 0 && age < 10000000) recv = now - age;
    }
    current_recv_us_ = recv;
    if (admit == Admit::kRun) {
      if (!run_known_ && join_first_) {
        set_run_id(msg.run_id);
        spdlog::info("joined run {} (the first message on {})", msg.run_id, ch);
      }
      if (!run_known_) return;  // not joined yet: its own run re-sends what matters
      if (msg.run_id != run_id_) {
        count_foreign(ch, msg.run_id);
        return;
      }
    }
    // An exception must not unwind through LCM's C dispatch: keep it for poll() to rethrow.
    try {
      handler(msg, recv);
    } catch (...) {
      if (!error_) error_ = std::current_exception();
    }
  });
}

template <typename Msg>
bool Bus::publish(const std::string& channel, const Msg& m) {
  // Stamped and, with a key, signed in a copy: the caller keeps its message (an Outbox
  // re-publishes it); the copy's mac is empty, so the copy costs no allocation.
  Msg msg = m;
  msg.run_id = run_id_;
  msg.mac_size = 0;
  msg.mac.clear();
  const int n = msg.getEncodedSize();
  const std::size_t size = static_cast<std::size_t>(n) + (auth_ ? MessageAuth::kMacSize : 0);
  if (out_.size() < size) out_.resize(size);
  if (msg.encode(out_.data(), 0, n) != n) throw std::logic_error(std::string("cannot encode a ") + Msg::getTypeName());
  if (auth_) auth_->sign(channel, out_.data(), size);  // mac_size 0 -> 32, then the mac
  return sent(lcm_.publish(channel, out_.data(), static_cast<unsigned int>(size)), channel);
}

}  // namespace feeddrive::service
