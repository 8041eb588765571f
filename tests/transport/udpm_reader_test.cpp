// The batched LCM receiver (service/udpm_reader.hpp): URL parsing and fragment reassembly as
// pure functions, then real LCM publications over UDP multicast read back through it. This
// binary runs inside a private network namespace (scripts/netns-run.sh, from ctest), where
// the loopback carries the multicast group.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/service/bus.hpp"
#include "feeddrive/service/udpm_reader.hpp"

using namespace feeddrive;
using namespace feeddrive::service;

namespace {

struct Got {
  std::string channel;
  std::vector<std::uint8_t> data;
  std::int64_t utime;
};

MessageSink collect(std::vector<Got>& out) {
  return [&out](std::string_view ch, const std::uint8_t* d, std::size_t n, std::int64_t t) {
    out.push_back({std::string(ch), std::vector<std::uint8_t>(d, d + n), t});
  };
}

void put32(std::vector<std::uint8_t>& b, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) b.push_back(static_cast<std::uint8_t>(v >> s));
}
void put16(std::vector<std::uint8_t>& b, std::uint16_t v) {
  b.push_back(static_cast<std::uint8_t>(v >> 8));
  b.push_back(static_cast<std::uint8_t>(v));
}

std::vector<std::uint8_t> short_datagram(std::uint32_t seq, const std::string& channel,
                                         const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> b;
  put32(b, 0x4c433032);
  put32(b, seq);
  b.insert(b.end(), channel.begin(), channel.end());
  b.push_back(0);
  b.insert(b.end(), payload.begin(), payload.end());
  return b;
}

/// LCM's fragments of one message: `parts` fragments of the payload, the channel in the first.
std::vector<std::vector<std::uint8_t>> fragments(std::uint32_t seq, const std::string& channel,
                                                 const std::vector<std::uint8_t>& payload, int parts) {
  std::vector<std::vector<std::uint8_t>> out;
  const std::size_t step = (payload.size() + parts - 1) / parts;
  for (int i = 0; i < parts; ++i) {
    const std::size_t off = i * step, end = std::min(payload.size(), off + step);
    std::vector<std::uint8_t> b;
    put32(b, 0x4c433033);
    put32(b, seq);
    put32(b, static_cast<std::uint32_t>(payload.size()));
    put32(b, static_cast<std::uint32_t>(off));
    put16(b, static_cast<std::uint16_t>(i));
    put16(b, static_cast<std::uint16_t>(parts));
    if (i == 0) {
      b.insert(b.end(), channel.begin(), channel.end());
      b.push_back(0);
    }
    b.insert(b.end(), payload.begin() + static_cast<long>(off), payload.begin() + static_cast<long>(end));
    out.push_back(b);
  }
  return out;
}

std::vector<std::uint8_t> random_bytes(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::uint8_t> v(n);
  for (auto& x : v) x = static_cast<std::uint8_t>(rng());
  return v;
}

std::int64_t now_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

TEST(ParseUdpmUrl, ReadsGroupPortAndReceiveBuffer) {
  const auto a = parse_udpm_url("udpm://239.1.2.3:9000?ttl=0&recv_buf_size=4194304");
  ASSERT_TRUE(a);
  EXPECT_EQ(a->group, "239.1.2.3");
  EXPECT_EQ(a->port, 9000);
  EXPECT_EQ(a->recv_buf_size, 4194304);
  // LCM's defaults when the URL leaves them out.
  const auto d = parse_udpm_url("udpm://");
  ASSERT_TRUE(d);
  EXPECT_EQ(d->group, "239.255.76.67");
  EXPECT_EQ(d->port, 7667);
  EXPECT_EQ(d->recv_buf_size, 0);
  EXPECT_FALSE(parse_udpm_url("memq://"));
  EXPECT_FALSE(parse_udpm_url("file:///tmp/x.lcmlog?mode=r"));
}

TEST(ParseUdpmUrl, BadPartsAreNamed) {
  try {
    parse_udpm_url("udpm://239.1.2.3:70000");
    FAIL() << "port 70000 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("port '70000'"), std::string::npos) << e.what();
  }
  try {
    parse_udpm_url("udpm://10.0.0.1:7667");
    FAIL() << "a unicast address accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'10.0.0.1' is not a multicast group"), std::string::npos) << e.what();
  }
  try {
    parse_udpm_url("udpm://239.1.2.3:7667?recv_buf_size=lots");
    FAIL() << "recv_buf_size=lots accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("recv_buf_size 'lots'"), std::string::npos) << e.what();
  }
}

TEST(Reassembler, PassesSmallMessagesThrough) {
  Reassembler r;
  std::vector<Got> got;
  const auto payload = random_bytes(300, 1);
  const auto d = short_datagram(7, "FD_STATE", payload);
  r.feed(d.data(), d.size(), 1, 123, collect(got));
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].channel, "FD_STATE");
  EXPECT_EQ(got[0].data, payload);
  EXPECT_EQ(got[0].utime, 123);
  // An empty payload is a message too.
  const auto e = short_datagram(8, "X", {});
  r.feed(e.data(), e.size(), 1, 0, collect(got));
  ASSERT_EQ(got.size(), 2u);
  EXPECT_TRUE(got[1].data.empty());
  EXPECT_EQ(r.malformed(), 0);
}

TEST(Reassembler, JoinsFragmentsInAnyOrderAndIgnoresDuplicates) {
  Reassembler r;
  std::vector<Got> got;
  const auto payload = random_bytes(200000, 2);
  auto f = fragments(42, "BIG", payload, 4);
  // Arrival order 3, 1, 1 (a duplicate), 0, 2: complete only after the last one.
  for (int i : {3, 1, 1, 0}) {
    r.feed(f[i].data(), f[i].size(), 9, 100 + i, collect(got));
    EXPECT_TRUE(got.empty());
  }
  r.feed(f[2].data(), f[2].size(), 9, 500, collect(got));
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].channel, "BIG");
  EXPECT_EQ(got[0].data, payload);
  EXPECT_EQ(got[0].utime, 500);  // the time its last datagram arrived
  EXPECT_EQ(r.pending(), 0u);
  EXPECT_EQ(r.malformed(), 0);
}

TEST(Reassembler, KeepsSendersApartAndDropsAnUnfinishedOlderMessage) {
  Reassembler r;
  std::vector<Got> got;
  const auto a = random_bytes(5000, 3), b = random_bytes(6000, 4);
  const auto fa = fragments(1, "A", a, 2), fb = fragments(1, "B", b, 2);
  // Two senders with the same sequence number, interleaved.
  r.feed(fa[0].data(), fa[0].size(), 1, 0, collect(got));
  r.feed(fb[0].data(), fb[0].size(), 2, 0, collect(got));
  r.feed(fb[1].data(), fb[1].size(), 2, 0, collect(got));
  r.feed(fa[1].data(), fa[1].size(), 1, 0, collect(got));
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].data, b);
  EXPECT_EQ(got[1].data, a);
  // Sender 1 loses a fragment of message 2, then sends message 3: message 2 is given up.
  const auto f2 = fragments(2, "A", a, 2), f3 = fragments(3, "A", b, 2);
  r.feed(f2[0].data(), f2[0].size(), 1, 0, collect(got));
  EXPECT_EQ(r.pending(), 1u);
  r.feed(f3[0].data(), f3[0].size(), 1, 0, collect(got));
  r.feed(f3[1].data(), f3[1].size(), 1, 0, collect(got));
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(got[2].data, b);
  EXPECT_EQ(r.pending(), 0u);
}

TEST(Reassembler, CountsMalformedDatagrams) {
  Reassembler r;
  std::vector<Got> got;
  const std::vector<std::uint8_t> tiny = {0x4c, 0x43};
  r.feed(tiny.data(), tiny.size(), 1, 0, collect(got));
  auto bad_magic = short_datagram(1, "A", {1, 2, 3});
  bad_magic[3] = '9';
  r.feed(bad_magic.data(), bad_magic.size(), 1, 0, collect(got));
  std::vector<std::uint8_t> no_nul;
  put32(no_nul, 0x4c433032);
  put32(no_nul, 1);
  no_nul.insert(no_nul.end(), {'A', 'B', 'C'});
  r.feed(no_nul.data(), no_nul.size(), 1, 0, collect(got));
  // A fragment that claims to reach past the end of its message.
  auto f = fragments(5, "A", random_bytes(1000, 5), 2);
  f[1][15] = 0xff;  // offset 500 (0x1f4) -> 511 (0x1ff): its 500 bytes would overrun the 1000
  r.feed(f[1].data(), f[1].size(), 1, 0, collect(got));
  EXPECT_TRUE(got.empty());
  EXPECT_EQ(r.malformed(), 4);
}

// Real liblcm publications on the multicast group, read by the batched reader: a small message
// and one that LCM fragments (100 kB), byte for byte, with kernel receive times.
TEST(UdpmReader, ReadsWhatLiblcmPublishes) {
  const std::string url = "udpm://239.255.76.67:7701?ttl=0&recv_buf_size=2097152";
  UdpmReader reader(*parse_udpm_url(url));
  EXPECT_GE(reader.recv_buf_size(), 2097152);  // the kernel reports twice what was granted
  lcm::LCM pub(url);
  ASSERT_TRUE(pub.good());
  const auto small = random_bytes(200, 6), big = random_bytes(100000, 7);
  const std::int64_t before = now_utime();
  pub.publish("T_SMALL", small.data(), static_cast<unsigned>(small.size()));
  pub.publish("T_BIG", big.data(), static_cast<unsigned>(big.size()));
  std::vector<Got> got;
  for (int i = 0; i < 200 && got.size() < 2; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    reader.drain(collect(got));
  }
  const std::int64_t after = now_utime();
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].channel, "T_SMALL");
  EXPECT_EQ(got[0].data, small);
  EXPECT_EQ(got[1].channel, "T_BIG");
  EXPECT_EQ(got[1].data, big);
  for (const Got& g : got) {
    EXPECT_GE(g.utime, before);
    EXPECT_LE(g.utime, after);
  }
  EXPECT_EQ(reader.malformed(), 0);
}

// A batched Bus and an event-driven one on the same group: typed messages arrive with their
// receive time, and a message of the wrong type on a channel is counted, not dispatched.
TEST(UdpmReader, BatchedBusDecodesAndCountsWrongTypes) {
  const std::string url = "udpm://239.255.76.67:7702?ttl=0&recv_buf_size=2097152";
  Bus batched(url, Receive::kBatched);
  ASSERT_TRUE(batched.batched());
  Bus event(url);
  EXPECT_FALSE(event.batched());
  batched.set_run_id(1);  // one run: the bus passes only its messages
  event.set_run_id(1);
  std::vector<std::int64_t> seqs;
  batched.subscribe<drive_state_t>("T_STATE", [&](const drive_state_t& m, std::int64_t) { seqs.push_back(m.seq); });
  drive_state_t s{};
  s.previous.seq = -1;
  for (std::int64_t k = 0; k < 50; ++k) {
    s.seq = k;
    event.publish("T_STATE", s);
  }
  control_command_t wrong{};
  event.publish("T_STATE", wrong);
  for (int i = 0; i < 200 && (seqs.size() < 50 || batched.invalid() < 1); ++i)
    batched.poll(std::chrono::milliseconds(5));
  ASSERT_EQ(seqs.size(), 50u);
  for (std::int64_t k = 0; k < 50; ++k) EXPECT_EQ(seqs[static_cast<std::size_t>(k)], k);
  EXPECT_EQ(batched.invalid(), 1);
}

// Outside udpm (here memq://, LCM's in-process transport) a batched Bus falls back to liblcm.
TEST(UdpmReader, OtherTransportsFallBackToLiblcm) {
  Bus bus("memq://", Receive::kBatched);
  EXPECT_FALSE(bus.batched());
  bus.set_run_id(1);
  int n = 0;
  bus.subscribe<control_command_t>("T_CMD", [&](const control_command_t&, std::int64_t) { ++n; });
  bus.publish("T_CMD", control_command_t{});
  bus.poll(std::chrono::milliseconds(100));
  EXPECT_EQ(n, 1);
}
