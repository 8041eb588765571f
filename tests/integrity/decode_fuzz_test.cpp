// The decode fuzzer (issue 19, point 11): every message type's valid encodings, mutated by seeded
// random byte flips, truncations and extensions, and by structure-aware mutations of the fields
// that size something (string lengths, array counts, the mac size, the fingerprint), fed through
// the receive path the processes use: a service::Bus over LCM's in-process transport memq://.
// Each case must end in exactly one of: the handler gets a message within the contract's bounds,
// or the bus counts one invalid message on that channel. Nothing throws, nothing crashes, and a
// valid message after the mutations still arrives (the subscription survives).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/process_status_t.hpp"
#include "feeddrive/reference_block_t.hpp"
#include "feeddrive/resend_request_t.hpp"
#include "feeddrive/run_info_t.hpp"
#include "feeddrive/run_summary_t.hpp"
#include "feeddrive/service/bus.hpp"
#include "feeddrive/wire.hpp"

namespace feeddrive {
namespace {

using service::Admit;
using service::Bus;
using Bytes = std::vector<std::uint8_t>;

std::string text(std::mt19937_64& rng, std::size_t max) {
  std::uniform_int_distribution<std::size_t> len(0, max);
  std::string s(len(rng), 'a');
  for (char& c : s) c = static_cast<char>('a' + rng() % 26);
  return s;
}
double num(std::mt19937_64& rng) { return std::uniform_real_distribution<double>(-1e3, 1e3)(rng); }
void mac(std::mt19937_64& rng, std::int16_t& size, std::vector<std::uint8_t>& m) {
  size = (rng() % 2) ? 32 : 0;
  m.assign(static_cast<std::size_t>(size), static_cast<std::uint8_t>(rng()));
}

// A valid message of each type, its content drawn from rng, within the contract's bounds.
template <typename Msg>
Msg valid(std::mt19937_64& rng);
template <>
control_command_t valid(std::mt19937_64& rng) {
  control_command_t m{};
  m.run_id = 1;
  m.seq = static_cast<std::int64_t>(rng() % 1000);
  m.t = num(rng), m.u = num(rng), m.u_unsaturated = num(rng), m.sliding = num(rng), m.z_estimate = num(rng);
  mac(rng, m.mac_size, m.mac);
  return m;
}
template <>
drive_state_t valid(std::mt19937_64& rng) {
  drive_state_t m{};
  m.run_id = 1;
  m.seq = static_cast<std::int64_t>(rng() % 1000);
  m.t = num(rng), m.x_measured = num(rng), m.v_measured = num(rng);
  m.truth.valid = true, m.truth.x = num(rng);
  m.previous.seq = m.seq - 1, m.previous.u = num(rng);
  mac(rng, m.mac_size, m.mac);
  return m;
}
template <>
process_status_t valid(std::mt19937_64& rng) {
  process_status_t m{};
  m.run_id = 1;
  m.role = text(rng, wire::Check<process_status_t>::kMax_role);
  m.state = text(rng, wire::Check<process_status_t>::kMax_state);
  m.message = text(rng, 200);
  mac(rng, m.mac_size, m.mac);
  return m;
}
template <>
reference_block_t valid(std::mt19937_64& rng) {
  reference_block_t m{};
  m.run_id = 1;
  m.first_seq = static_cast<std::int64_t>(rng() % 1000);
  m.count = static_cast<std::int32_t>(1 + rng() % 16);
  m.refs.resize(static_cast<std::size_t>(m.count));
  for (int i = 0; i < m.count; ++i)
    m.refs[static_cast<std::size_t>(i)].seq = m.first_seq + i, m.refs[static_cast<std::size_t>(i)].position = num(rng);
  mac(rng, m.mac_size, m.mac);
  return m;
}
template <>
resend_request_t valid(std::mt19937_64& rng) {
  resend_request_t m{};
  m.run_id = 1;
  m.requester = text(rng, wire::Check<resend_request_t>::kMax_requester);
  m.channel = text(rng, wire::Check<resend_request_t>::kMax_channel);
  mac(rng, m.mac_size, m.mac);
  return m;
}
template <>
run_info_t valid(std::mt19937_64& rng) {
  run_info_t m{};
  m.run_id = 1;
  m.scenario = text(rng, 40);
  m.mode = "lockstep";
  m.plant.resize(1 + rng() % 4);  // run_info_t.plant: the drive's parameters, 1..96 of them
  for (parameter_t& p : m.plant) {
    p.key = text(rng, wire::Check<parameter_t>::kMax_key);
    p.value = num(rng);
    p.name = text(rng, wire::Check<parameter_t>::kMax_name);
  }
  m.plant_count = static_cast<std::int16_t>(m.plant.size());
  mac(rng, m.mac_size, m.mac);
  return m;
}
template <>
run_summary_t valid(std::mt19937_64& rng) {
  run_summary_t m{};
  m.run_id = 1;
  m.scenario = text(rng, 40);
  m.failure = text(rng, 300);
  mac(rng, m.mac_size, m.mac);
  return m;
}

template <typename Msg>
Bytes encode(const Msg& m) {
  Bytes b(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(b.data(), 0, static_cast<int>(b.size())), static_cast<int>(b.size()));
  return b;
}

void put_be(Bytes& b, std::size_t at, std::int64_t v, std::size_t size) {
  for (std::size_t i = 0; i < size && at + i < b.size(); ++i)
    b[at + i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(v) >> (8 * (size - 1 - i)));
}

// The values a length or count is set to: the edges of its range and the ones that crashed or
// pinned memory before (issue 19: length 0, count -1, mac_size -1, count 10^7).
const std::int64_t kHostile[] = {0,    -1,    1,      2,     15,       16,         17,           31,
                                 32,   33,    63,     64,    255,      256,        1023,         1024,
                                 1025, 32767, -32768, 65535, 10000000, 2147483647, -2147483648LL};

// Offsets of the 4-byte lengths of the strings in an encoding: the big-endian value len+1 right
// before those bytes and a NUL after them (found by content: each string is known).
std::vector<std::size_t> string_length_offsets(const Bytes& b, const std::vector<std::string>& strings) {
  std::vector<std::size_t> at;
  for (const std::string& s : strings) {
    const std::size_t len = s.size() + 1;
    for (std::size_t i = 8; i + 4 + len <= b.size(); ++i) {
      const std::uint32_t v =
          (std::uint32_t{b[i]} << 24) | (std::uint32_t{b[i + 1]} << 16) | (std::uint32_t{b[i + 2]} << 8) | b[i + 3];
      if (v == len && std::memcmp(&b[i + 4], s.data(), s.size()) == 0 && b[i + 4 + s.size()] == 0) {
        at.push_back(i);
        break;
      }
    }
  }
  return at;
}

std::vector<std::string> strings_of(const process_status_t& m) { return {m.role, m.state, m.message}; }
std::vector<std::string> strings_of(const resend_request_t& m) { return {m.requester, m.channel}; }
std::vector<std::string> strings_of(const run_info_t& m) {
  std::vector<std::string> s = {m.scenario, m.mode};
  for (const parameter_t& p : m.plant) s.insert(s.end(), {p.key, p.name});
  return s;
}
std::vector<std::string> strings_of(const run_summary_t& m) { return {m.scenario, m.failure}; }
template <typename Msg>
std::vector<std::string> strings_of(const Msg&) {
  return {};
}

// Offsets of the fields that size something other than strings: the mac size (its place is
// known from the end: mac_size is the last field but the mac bytes) and a block's count.
template <typename Msg>
std::vector<std::pair<std::size_t, std::size_t>> count_offsets(const Msg& m, const Bytes& b) {
  std::vector<std::pair<std::size_t, std::size_t>> at;  // (offset, size)
  at.emplace_back(b.size() - m.mac.size() - 2, 2);
  if constexpr (std::is_same_v<Msg, reference_block_t>) at.emplace_back(8 + 8 + 8, 4);
  // run_info_t.plant_count: after the fingerprint, run_id, utime, run_nonce, scenario, mode,
  // control_period and steps.
  if constexpr (std::is_same_v<Msg, run_info_t>)
    at.emplace_back(8 + 3 * 8 + (4 + m.scenario.size() + 1) + (4 + m.mode.size() + 1) + 2 * 8, 2);
  return at;
}

template <typename Msg>
bool within_bounds(const Msg& m) {
  if constexpr (std::is_same_v<Msg, reference_block_t>)
    if (m.refs.size() > 16 || m.count < 1) return false;
  if constexpr (std::is_same_v<Msg, run_info_t>)
    if (m.plant.size() > 96 || m.plant_count < 0) return false;
  return m.mac.size() <= 32 && m.getEncodedSize() <= static_cast<int>(wire::Check<Msg>::kMaxEncoded);
}

struct Outcome {
  std::int64_t delivered{0}, invalid{0};
};

// Feeds `cases` mutations of valid Msg encodings through a Bus on memq:// and checks each ends
// in exactly one outcome; `out` gets how many were delivered and how many counted invalid.
template <typename Msg>
void fuzz(std::uint64_t seed, int cases, Outcome& out) {
  Bus bus("memq://", service::Receive::kEvent);
  bus.set_run_id(1);
  const std::string ch = std::string("FUZZ_") + Msg::getTypeName();
  std::int64_t delivered = 0;
  bool in_bounds = true;
  bus.subscribe<Msg>(
      ch,
      [&](const Msg& m, std::int64_t) {
        ++delivered;
        in_bounds = in_bounds && within_bounds(m);
      },
      Admit::kAnyRun);
  std::mt19937_64 rng(seed);
  for (int k = 0; k < cases; ++k) {
    const Msg m = valid<Msg>(rng);
    Bytes b = encode(m);
    switch (k % 6) {
      case 0: {  // random byte flips
        const int flips = 1 + static_cast<int>(rng() % 4);
        for (int i = 0; i < flips; ++i) b[rng() % b.size()] ^= static_cast<std::uint8_t>(1 + rng() % 255);
        break;
      }
      case 1:  // truncation
        b.resize(rng() % b.size());
        break;
      case 2: {  // trailing bytes, or far beyond the contract's size
        const std::size_t extra = (rng() % 3 == 0) ? 70000 : 1 + rng() % 64;
        b.resize(b.size() + extra, static_cast<std::uint8_t>(rng()));
        break;
      }
      case 3: {  // a string's length field
        const auto at = string_length_offsets(b, strings_of(m));
        if (at.empty()) {
          b[rng() % b.size()] ^= 0xFF;
          break;
        }
        put_be(b, at[rng() % at.size()], kHostile[rng() % std::size(kHostile)], 4);
        break;
      }
      case 4: {  // a count or the mac size
        const auto at = count_offsets(m, b);
        const auto [off, size] = at[rng() % at.size()];
        put_be(b, off, kHostile[rng() % std::size(kHostile)], size);
        break;
      }
      default:  // the fingerprint
        put_be(b, 0, static_cast<std::int64_t>(rng()), 8);
        break;
    }
    const std::int64_t before_d = delivered, before_i = bus.invalid();
    ASSERT_NO_THROW({
      bus.publish_raw(ch, b.data(), b.size());
      bus.poll(std::chrono::microseconds(0));
    }) << Msg::getTypeName()
       << " case " << k;
    const std::int64_t d = delivered - before_d, i = bus.invalid() - before_i;
    // Exactly one outcome per datagram (a mutation can leave a valid message, e.g. a flipped
    // double or a string length set to its own value).
    ASSERT_EQ(d + i, 1) << Msg::getTypeName() << " case " << k << ": delivered " << d << ", invalid " << i;
    out.delivered += d;
    out.invalid += i;
  }
  EXPECT_TRUE(in_bounds) << Msg::getTypeName() << ": a delivered message broke the contract's bounds";
  EXPECT_EQ(bus.invalid_by_channel()[ch], out.invalid);
  // The subscription survives: a valid message still arrives.
  const Bytes ok = encode(valid<Msg>(rng));
  const std::int64_t before = delivered;
  bus.publish_raw(ch, ok.data(), ok.size());
  bus.poll(std::chrono::microseconds(0));
  EXPECT_EQ(delivered, before + 1);
}

// 7 types x 300 cases = 2,100 mutated datagrams each CI run, seeds fixed. Most mutations make the
// message invalid; the structure-aware ones also reach the decode of valid-but-odd values.
constexpr int kCases = 300;

template <typename Msg>
void fuzz_type(std::uint64_t seed) {
  Outcome o;
  fuzz<Msg>(seed, kCases, o);
  EXPECT_GT(o.invalid, kCases / 2) << Msg::getTypeName();  // most mutations break the encoding
  EXPECT_GT(o.delivered, 0) << Msg::getTypeName();         // some leave it valid: those still decode
}

TEST(DecodeFuzz, ControlCommand) { fuzz_type<control_command_t>(101); }
TEST(DecodeFuzz, DriveState) { fuzz_type<drive_state_t>(102); }
TEST(DecodeFuzz, ProcessStatus) { fuzz_type<process_status_t>(103); }
TEST(DecodeFuzz, ReferenceBlock) { fuzz_type<reference_block_t>(104); }
TEST(DecodeFuzz, ResendRequest) { fuzz_type<resend_request_t>(105); }
TEST(DecodeFuzz, RunInfo) { fuzz_type<run_info_t>(106); }
TEST(DecodeFuzz, RunSummary) { fuzz_type<run_summary_t>(107); }

// The datagrams of issue 19 that killed every process of a run, each sent once.
TEST(DecodeFuzz, TheDatagramsThatKilledARunAreCountedAndDropped) {
  std::mt19937_64 rng(7);
  Bus bus("memq://", service::Receive::kEvent);
  bus.set_run_id(1);
  int status = 0, blocks = 0;
  bus.subscribe<process_status_t>(
      "FD_STATUS", [&](const process_status_t&, std::int64_t) { ++status; }, Admit::kAnyRun);
  bus.subscribe<reference_block_t>("FD_REF", [&](const reference_block_t&, std::int64_t) { ++blocks; });
  auto send = [&](const std::string& ch, const Bytes& b) {
    ASSERT_NO_THROW({
      bus.publish_raw(ch, b.data(), b.size());
      bus.poll(std::chrono::microseconds(0));
    });
  };
  process_status_t st = valid<process_status_t>(rng);
  st.role = "plant";
  st.mac_size = 0;
  st.mac.clear();
  Bytes b = encode(st);
  put_be(b, string_length_offsets(b, {st.role})[0], 0, 4);  // role of length 0
  send("FD_STATUS", b);
  reference_block_t rb = valid<reference_block_t>(rng);
  b = encode(rb);
  put_be(b, 24, -1, 4);  // count = -1
  send("FD_REF", b);
  put_be(b, 24, 10000000, 4);  // count = 10^7: would allocate 560 MB before the bytes are checked
  send("FD_REF", b);
  b = encode(rb);
  put_be(b, b.size() - rb.mac.size() - 2, -1, 2);  // mac_size = -1
  send("FD_REF", b);
  EXPECT_EQ(status, 0);
  EXPECT_EQ(blocks, 0);
  EXPECT_EQ(bus.invalid(), 4);
  EXPECT_EQ(bus.invalid_by_channel()["FD_STATUS"], 1);
  EXPECT_EQ(bus.invalid_by_channel()["FD_REF"], 3);
  // ... and the run goes on: the next valid block is delivered.
  send("FD_REF", encode(rb));
  EXPECT_EQ(blocks, 1);
}

// decode_untrusted names the field and the value that broke the bound.
TEST(DecodeUntrusted, NamesTheFieldOutOfBounds) {
  std::mt19937_64 rng(9);
  reference_block_t rb = valid<reference_block_t>(rng);
  Bytes b = encode(rb);
  put_be(b, 24, 10000000, 4);
  reference_block_t out;
  std::string why;
  EXPECT_FALSE(wire::decode_untrusted(b.data(), b.size(), out, &why));
  EXPECT_EQ(why, "reference_block_t.count = 10000000 (bound 1..16)");
  EXPECT_TRUE(out.refs.empty());  // nothing was allocated for it
}

// A publisher cuts a string to its field's bound, not inside a UTF-8 sequence.
TEST(DecodeUntrusted, FitCutsAtTheBoundOnACharacterBoundary) {
  EXPECT_EQ(wire::fit("abc", 5), "abc");
  EXPECT_EQ(wire::fit("abcdef", 3), "abc");
  EXPECT_EQ(wire::fit("a\xC3\xA9", 2), "a");  // 'é' is two bytes: not cut in half
}

}  // namespace
}  // namespace feeddrive
