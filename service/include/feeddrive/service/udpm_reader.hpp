#pragma once
// A batched receiver for LCM's UDP multicast transport, for the processes that are off a step's
// critical path (the monitor and the trajectory).
//
// Why not liblcm's own receive path: LCM 1.3.1 (Debian 12) reads its socket in a receive
// thread that sleeps in select() and wakes for every datagram on the multicast group, whatever
// its channel, then wakes the main thread through a pipe for the subscribed ones. Every process
// on the group therefore pays a wake-up for each of a step's datagrams. Measured on the 2-core
// development VM, where a switch between processes is expensive: two LCM processes that merely
// sit on the group cut a two-process ping-pong from 20,600 to 14,400 round trips/s on one core;
// two processes that drain the same group in batches (this class) leave it at 19,800
// (bench/lockstep_bench.sh; docs/lcm-contract.md, "Receiving in batches"). A recorder does not need a wake-up per
// datagram: it sleeps for a batch interval and then takes everything queued, so the kernel
// only queues the datagrams on its socket and nobody is woken.
//
// The wire format is LCM's UDP multicast protocol
// (https://lcm-proj.github.io/lcm/content/udp-multicast-protocol.html), big-endian:
//   small message: u32 magic "LC02", u32 sequence number, channel, NUL, payload;
//   fragment:      u32 magic "LC03", u32 sequence number, u32 payload size, u32 offset of this
//                  fragment in the payload, u16 fragment number, u16 fragment count, then (first
//                  fragment only) channel and NUL, then the fragment's part of the payload.
// Publishing stays with liblcm; only the receive side is here.

#include <netinet/in.h>

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace feeddrive::service {

/// The multicast group and port of an LCM "udpm://GROUP:PORT?ttl=..&recv_buf_size=.." URL.
struct UdpmAddress {
  std::string group{"239.255.76.67"};  ///< LCM's default group
  int port{7667};                      ///< LCM's default port
  int recv_buf_size{0};                ///< requested SO_RCVBUF [bytes]; 0: the kernel's default
};

/// Parses an LCM URL. nullopt if it is not a udpm:// URL (memq://, file://, ...). Throws
/// std::invalid_argument naming the URL and the bad part (group, port or option value).
std::optional<UdpmAddress> parse_udpm_url(const std::string& url);

/// One complete LCM message: its channel and payload, and the wall-clock time [us since the
/// epoch] at which the kernel queued its (last) datagram.
using MessageSink =
    std::function<void(std::string_view channel, const std::uint8_t* data, std::size_t size, std::int64_t recv_utime)>;

/// Turns datagrams into LCM messages: small messages pass through, fragments are reassembled
/// per (sender, sequence number). Pure: no sockets. Malformed datagrams (bad magic, truncated
/// header, no channel terminator, inconsistent fragment) are counted and dropped.
class Reassembler {
 public:
  /// Returns true if the datagram completed a message (passed to `sink`).
  bool feed(const std::uint8_t* d, std::size_t n, std::uint64_t sender, std::int64_t recv_utime,
            const MessageSink& sink);
  std::int64_t malformed() const { return malformed_; }
  std::size_t pending() const { return partial_.size(); }

 private:
  struct Partial {
    std::string channel;
    std::vector<std::uint8_t> data;
    std::vector<bool> have;
    std::size_t received{0};
  };
  std::map<std::pair<std::uint64_t, std::uint32_t>, Partial> partial_;
  std::int64_t malformed_{0};
};

/// A non-blocking socket joined to the group of a udpm URL, read in batches with recvmmsg.
class UdpmReader {
 public:
  /// Throws std::runtime_error naming the address when the socket cannot be set up.
  explicit UdpmReader(const UdpmAddress& a);
  ~UdpmReader();
  UdpmReader(const UdpmReader&) = delete;
  UdpmReader& operator=(const UdpmReader&) = delete;

  /// Reads every datagram queued now, without waiting, and passes each complete message to
  /// `sink`. Returns the number of messages delivered.
  std::size_t drain(const MessageSink& sink);

  std::int64_t malformed() const { return reassembler_.malformed(); }
  /// While drain() passes a message to its sink: the sender's address and port, "IP:PORT" (the
  /// UDP source of its last datagram). It names who sent a message (a conflict's two senders).
  std::string current_source() const;
  /// The socket, for waiting on it (poll/ppoll).
  int fd() const { return fd_; }
  /// The receive buffer the kernel granted [bytes].
  int recv_buf_size() const { return granted_; }

 private:
  int fd_{-1};
  int granted_{0};
  Reassembler reassembler_;
  std::vector<std::uint8_t> buf_;
  std::uint64_t current_{0};  ///< the sender of the datagram being passed on (address << 16 | port)
};

}  // namespace feeddrive::service
