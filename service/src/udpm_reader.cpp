#include "feeddrive/service/udpm_reader.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace feeddrive::service {
namespace {

constexpr std::uint32_t kMagicShort = 0x4c433032;  // "LC02"
constexpr std::uint32_t kMagicLong = 0x4c433033;   // "LC03"
constexpr std::size_t kShortHeader = 8;
constexpr std::size_t kLongHeader = 20;
constexpr std::size_t kMaxDatagram = 65536;
constexpr std::size_t kBatch = 16;  // datagrams per recvmmsg call
// Fragmented messages: feeddrive's own are all below 8.5 kB (wire_check.hpp's kMaxEncoded; LCM
// fragments above 64 kB) and never fragmented, so a fragmented one is another application's or
// forged. At most kMaxPartial of at most kMaxPayload bytes are kept while their fragments come:
// 8 MB per process, whatever is sent.
constexpr std::size_t kMaxPayload = 1024u * 1024u;
constexpr std::size_t kMaxPartial = 8;

std::uint32_t be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | std::uint32_t{p[3]};
}
std::uint16_t be16(const std::uint8_t* p) { return static_cast<std::uint16_t>((p[0] << 8) | p[1]); }

int parse_int(const std::string& url, const std::string& what, const std::string& text, long lo, long hi) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno != 0 || v < lo || v > hi)
    throw std::invalid_argument("LCM URL '" + url + "': " + what + " '" + text + "' is not an integer in [" +
                                std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return static_cast<int>(v);
}

}  // namespace

std::optional<UdpmAddress> parse_udpm_url(const std::string& url) {
  const std::string scheme = "udpm://";
  if (url.compare(0, scheme.size(), scheme) != 0) return std::nullopt;
  UdpmAddress a;
  const std::string rest = url.substr(scheme.size());
  const std::size_t q = rest.find('?');
  const std::string hostport = rest.substr(0, q);
  if (!hostport.empty()) {
    const std::size_t colon = hostport.find(':');
    a.group = hostport.substr(0, colon);
    if (colon != std::string::npos) a.port = parse_int(url, "port", hostport.substr(colon + 1), 1, 65535);
    in_addr probe{};
    if (inet_aton(a.group.c_str(), &probe) == 0 || !IN_MULTICAST(ntohl(probe.s_addr)))
      throw std::invalid_argument("LCM URL '" + url + "': '" + a.group + "' is not a multicast group address");
  }
  if (q == std::string::npos) return a;
  std::size_t start = q + 1;
  while (start <= rest.size()) {
    const std::size_t amp = std::min(rest.find('&', start), rest.size());
    const std::string opt = rest.substr(start, amp - start);
    const std::size_t eq = opt.find('=');
    if (eq != std::string::npos && opt.substr(0, eq) == "recv_buf_size")
      a.recv_buf_size = parse_int(url, "recv_buf_size", opt.substr(eq + 1), 0, 1 << 30);
    start = amp + 1;
  }
  return a;
}

bool Reassembler::feed(const std::uint8_t* d, std::size_t n, std::uint64_t sender, std::int64_t recv_utime,
                       const MessageSink& sink) {
  if (n < kShortHeader) {
    ++malformed_;
    return false;
  }
  const std::uint32_t magic = be32(d);
  if (magic == kMagicShort) {
    const auto* name = d + kShortHeader;
    const auto* nul = static_cast<const std::uint8_t*>(std::memchr(name, 0, n - kShortHeader));
    if (nul == nullptr) {
      ++malformed_;
      return false;
    }
    const std::string_view channel(reinterpret_cast<const char*>(name), static_cast<std::size_t>(nul - name));
    sink(channel, nul + 1, static_cast<std::size_t>(d + n - (nul + 1)), recv_utime);
    return true;
  }
  if (magic != kMagicLong || n < kLongHeader) {
    ++malformed_;
    return false;
  }
  const std::uint32_t seqno = be32(d + 4);
  const std::uint32_t size = be32(d + 8);
  const std::uint32_t offset = be32(d + 12);
  const std::uint16_t no = be16(d + 16);
  const std::uint16_t count = be16(d + 18);
  const std::uint8_t* body = d + kLongHeader;
  std::size_t body_n = n - kLongHeader;
  std::string channel;
  if (no == 0) {
    const auto* nul = static_cast<const std::uint8_t*>(std::memchr(body, 0, body_n));
    if (nul == nullptr) {
      ++malformed_;
      return false;
    }
    channel.assign(reinterpret_cast<const char*>(body), static_cast<std::size_t>(nul - body));
    body_n -= static_cast<std::size_t>(nul + 1 - body);
    body = nul + 1;
  }
  if (count == 0 || no >= count || size > kMaxPayload || offset > size || body_n > size - offset) {
    ++malformed_;
    return false;
  }
  const auto key = std::make_pair(sender, seqno);
  auto it = partial_.find(key);
  if (it == partial_.end()) {
    // A sender's new message supersedes its unfinished older ones: their lost fragments will
    // never come (LCM does not resend).
    for (auto old = partial_.begin(); old != partial_.end();)
      old = old->first.first == sender ? partial_.erase(old) : std::next(old);
    if (partial_.size() >= kMaxPartial) {  // many senders at once: the bound wins over completeness
      partial_.erase(partial_.begin());
      ++malformed_;
    }
    Partial p;
    p.data.resize(size);
    p.have.assign(count, false);
    it = partial_.emplace(key, std::move(p)).first;
  }
  Partial& p = it->second;
  if (p.data.size() != size || p.have.size() != count) {
    ++malformed_;
    partial_.erase(it);
    return false;
  }
  if (p.have[no]) return false;  // a duplicate fragment
  p.have[no] = true;
  ++p.received;
  if (no == 0) p.channel = std::move(channel);
  if (body_n > 0) std::memcpy(p.data.data() + offset, body, body_n);
  if (p.received < count) return false;
  const Partial done = std::move(p);
  partial_.erase(it);
  sink(done.channel, done.data.data(), done.data.size(), recv_utime);
  return true;
}

UdpmReader::UdpmReader(const UdpmAddress& a) : buf_(kBatch * kMaxDatagram) {
  const std::string where = a.group + ":" + std::to_string(a.port);
  fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
  if (fd_ < 0) throw std::runtime_error("cannot open a UDP socket for " + where + ": " + std::strerror(errno));
  const auto fail = [&](const std::string& what) {
    const std::string msg = what + " for " + where + " failed: " + std::strerror(errno) +
                            " (is there a multicast route? see docs/lcm-contract.md)";
    ::close(fd_);
    fd_ = -1;
    throw std::runtime_error(msg);
  };
  const int one = 1;
  // As liblcm: several processes on one machine bind the same port.
  if (::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0) fail("SO_REUSEADDR");
  // The kernel buffer is this reader's only queue between batches (liblcm has its own ring
  // buffer behind its receive thread), so it gets the size the URL asks for: SO_RCVBUF, capped
  // at net.core.rmem_max, and where that falls short and the process may (CAP_NET_ADMIN),
  // SO_RCVBUFFORCE. The kernel reports twice the size asked for (its bookkeeping).
  socklen_t len = sizeof granted_;
  if (a.recv_buf_size > 0) {
    const int want = a.recv_buf_size;
    if (::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &want, sizeof want) != 0) fail("SO_RCVBUF");
    ::getsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &granted_, &len);
    if (granted_ < 2 * want) (void)::setsockopt(fd_, SOL_SOCKET, SO_RCVBUFFORCE, &want, sizeof want);
  }
  len = sizeof granted_;
  ::getsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &granted_, &len);
  // The kernel's receive time of each datagram: latencies stay exact although reads are batched.
  if (::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMP, &one, sizeof one) != 0) fail("SO_TIMESTAMP");
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_ANY);
  addr.sin_port = htons(static_cast<std::uint16_t>(a.port));
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) fail("bind");
  ip_mreq mreq{};
  inet_aton(a.group.c_str(), &mreq.imr_multiaddr);
  mreq.imr_interface.s_addr = htonl(INADDR_ANY);
  if (::setsockopt(fd_, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) != 0) fail("joining the group");
  if (::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) | O_NONBLOCK) != 0) fail("O_NONBLOCK");
}

UdpmReader::~UdpmReader() {
  if (fd_ >= 0) ::close(fd_);
}

std::string UdpmReader::current_source() const {
  const auto addr = static_cast<std::uint32_t>(current_ >> 16);  // network byte order, as in sin_addr
  const auto* b = reinterpret_cast<const unsigned char*>(&addr);
  const auto port = static_cast<std::uint16_t>(current_ & 0xFFFF);
  return std::to_string(b[0]) + "." + std::to_string(b[1]) + "." + std::to_string(b[2]) + "." + std::to_string(b[3]) +
         ":" + std::to_string(ntohs(port));
}

std::size_t UdpmReader::drain(const MessageSink& sink) {
  std::size_t delivered = 0;
  mmsghdr msgs[kBatch];
  iovec iov[kBatch];
  sockaddr_in from[kBatch];
  alignas(cmsghdr) char control[kBatch][CMSG_SPACE(sizeof(timeval))];
  for (;;) {
    for (std::size_t i = 0; i < kBatch; ++i) {
      iov[i] = {buf_.data() + i * kMaxDatagram, kMaxDatagram};
      msgs[i] = {};
      msgs[i].msg_hdr.msg_name = &from[i];
      msgs[i].msg_hdr.msg_namelen = sizeof from[i];
      msgs[i].msg_hdr.msg_iov = &iov[i];
      msgs[i].msg_hdr.msg_iovlen = 1;
      msgs[i].msg_hdr.msg_control = control[i];
      msgs[i].msg_hdr.msg_controllen = sizeof control[i];
    }
    const int got = ::recvmmsg(fd_, msgs, kBatch, MSG_DONTWAIT, nullptr);
    if (got < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN || errno == EWOULDBLOCK) return delivered;
      throw std::runtime_error(std::string("reading the LCM multicast socket failed: ") + std::strerror(errno));
    }
    for (int i = 0; i < got; ++i) {
      std::int64_t utime = 0;
      for (cmsghdr* c = CMSG_FIRSTHDR(&msgs[i].msg_hdr); c != nullptr; c = CMSG_NXTHDR(&msgs[i].msg_hdr, c)) {
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMP) {
          timeval tv{};
          std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
          utime = static_cast<std::int64_t>(tv.tv_sec) * 1000000 + tv.tv_usec;
        }
      }
      const std::uint64_t sender = (std::uint64_t{from[i].sin_addr.s_addr} << 16) | from[i].sin_port;
      current_ = sender;
      if (reassembler_.feed(static_cast<const std::uint8_t*>(iov[i].iov_base), msgs[i].msg_len, sender, utime, sink))
        ++delivered;
    }
    if (static_cast<std::size_t>(got) < kBatch) return delivered;
  }
}

}  // namespace feeddrive::service
