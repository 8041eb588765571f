#include "feeddrive/service/bus.hpp"

#include <poll.h>
#include <spdlog/spdlog.h>

#include <cerrno>
#include <cstdio>
#include <ctime>
#include <stdexcept>

namespace feeddrive::service {

std::string default_lcm_url() { return "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304"; }

std::int64_t wall_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::int64_t mono_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

Bus::Bus(const std::string& url, Receive receive, lcm_t* shared)
    : url_(url),
      shared_(shared != nullptr),
      lcm_(shared != nullptr ? lcm::LCM(shared) : lcm::LCM(url)),
      receive_(receive) {
  if (!lcm_.good())
    throw std::runtime_error("cannot open LCM at '" + url + "' (is there a multicast route? see docs/lcm-contract.md)");
  // Direct and batched: liblcm only publishes (it opens its receive socket and thread on the
  // first subscribe or handle, which then never come); our reader takes the group's datagrams.
  if (receive != Receive::kEvent && !shared_)
    if (const std::optional<UdpmAddress> a = parse_udpm_url(url)) reader_ = std::make_unique<UdpmReader>(*a);
  if (!reader_) receive_ = Receive::kEvent;
}

Bus::~Bus() {
  // lcm::LCM's destructor frees its subscriptions without taking them off the instance: on a
  // shared one (which lives on) a later message would reach the freed handlers.
  if (shared_)
    for (lcm::Subscription* s : subscriptions_) lcm_.unsubscribe(s);
}

bool Bus::log_due(std::int64_t& last) {
  const std::int64_t now = mono_us();
  if (last >= 0 && now - last < 1000000) return false;
  last = now;
  return true;
}

void Bus::count_foreign(const std::string& channel, std::int64_t run_id, const std::string& role) {
  ++foreign_;
  if (events_.foreign) events_.foreign(channel, run_id, role);
  else if (reports_ && log_due(last_foreign_log_us_))
    spdlog::warn(
        "ignored a message of another run (run id {}, this run {}) on {}: {} so far (a second run on this "
        "group, or a replayed log)",
        run_id, run_id_, channel, foreign_);
}

bool Bus::publish_raw(const std::string& channel, const std::uint8_t* data, std::size_t size) {
  return sent(lcm_.publish(channel, data, static_cast<unsigned int>(size)), channel);
}

bool Bus::sent(int rc, const std::string& channel) {
  if (rc == 0) return true;
  ++send_errors_;
  if (log_due(last_send_error_log_us_))
    spdlog::warn("cannot send on {}: LCM publish failed ({} send errors so far)", channel, send_errors_);
  return false;
}

void Bus::count_invalid(const std::string& channel, const std::uint8_t* data, std::size_t size,
                        const std::string& why) {
  ++invalid_;
  ++invalid_by_channel_[channel];
  if (events_.undecodable) events_.undecodable(channel, data, size, why);
  else if (reports_ && log_due(last_invalid_log_us_))
    spdlog::warn("dropped an invalid message on {}: {} ({} so far)", channel, why, invalid_);
}

std::map<std::string, std::int64_t> Bus::invalid_by_channel() const {
  std::map<std::string, std::int64_t> m = invalid_by_channel_;
  if (reader_ && reader_->malformed() > 0) m[""] += reader_->malformed();
  return m;
}

void Bus::subscribe_raw(const std::string& channel,
                        std::function<void(const lcm::ReceiveBuffer*, const std::string&)> f) {
  raws_.push_back(std::make_unique<Raw>(Raw{std::move(f)}));
  if (reader_) {
    batched_subs_[channel].push_back(raws_.back().get());
    return;
  }
  lcm::Subscription* sub = lcm_.subscribe(channel, &Raw::handle, raws_.back().get());
  // LCM drops silently when a subscription's queue overflows (default 30 messages).
  if (sub != nullptr) {
    sub->setQueueCapacity(100000);
    subscriptions_.push_back(sub);
  }
}

void Bus::rethrow_handler_error() {
  if (!error_) return;
  std::exception_ptr e = error_;
  error_ = nullptr;
  std::rethrow_exception(e);
}

bool Bus::poll(std::chrono::microseconds timeout) {
  switch (receive_) {
    case Receive::kDirect: return poll_direct(timeout);
    case Receive::kBatched: return poll_batched(timeout);
    case Receive::kEvent: break;
  }
  return poll_event(timeout);
}

std::size_t Bus::drain() {
  std::string channel;
  const std::size_t n =
      reader_->drain([&](std::string_view ch, const std::uint8_t* d, std::size_t size, std::int64_t utime) {
        if (tap_) tap_(ch, d, size, utime);
        channel.assign(ch);
        const auto it = batched_subs_.find(channel);
        if (it == batched_subs_.end()) return;
        lcm::ReceiveBuffer rbuf{const_cast<std::uint8_t*>(d), static_cast<std::uint32_t>(size), utime};
        for (Raw* r : it->second) r->handle(&rbuf, channel);
      });
  rethrow_handler_error();
  return n;
}

bool Bus::poll_batched(std::chrono::microseconds timeout) {
  // Sleep first, never on the socket: datagrams queue meanwhile without waking anyone.
  const std::int64_t wait_us = std::max<std::int64_t>(std::min(timeout, kBatchInterval).count(), 0);
  struct timespec ts {
    static_cast<time_t>(wait_us / 1000000), static_cast<long>((wait_us % 1000000) * 1000)
  };
  ::nanosleep(&ts, nullptr);  // EINTR (a signal): drain what is there and return
  return drain() > 0;
}

bool Bus::poll_direct(std::chrono::microseconds timeout) {
  // One wait on the socket (returns at once when something is queued), then take everything.
  const std::int64_t wait_us = std::max<std::int64_t>(timeout.count(), 0);
  struct pollfd p {
    reader_->fd(), POLLIN, 0
  };
  struct timespec ts {
    static_cast<time_t>(wait_us / 1000000), static_cast<long>((wait_us % 1000000) * 1000)
  };
  const int r = ::ppoll(&p, 1, &ts, nullptr);
  if (r < 0 && errno != EINTR) throw std::runtime_error("poll on the LCM socket failed");
  return r > 0 && drain() > 0;
}

bool Bus::poll_event(std::chrono::microseconds timeout) {
  const int fd = lcm_.getFileno();
  bool handled = false;
  const std::int64_t deadline = mono_us() + timeout.count();
  for (;;) {
    const std::int64_t left = deadline - mono_us();
    struct pollfd p {
      fd, POLLIN, 0
    };
    const std::int64_t wait_us = handled ? 0 : std::max<std::int64_t>(left, 0);
    struct timespec ts {
      static_cast<time_t>(wait_us / 1000000), static_cast<long>((wait_us % 1000000) * 1000)
    };
    const int r = ::ppoll(&p, 1, &ts, nullptr);
    if (r < 0) {
      if (errno == EINTR) return handled;
      throw std::runtime_error("poll on the LCM socket failed");
    }
    if (r == 0) return handled;  // nothing (more) waiting
    if (lcm_.handle() != 0) throw std::runtime_error("lcm handle() failed");
    handled = true;
    rethrow_handler_error();
  }
}

}  // namespace feeddrive::service
