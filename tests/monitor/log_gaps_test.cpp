// Gaps in LCM logs are never silent (issue 13, point 5). A run of N lockstep steps is written as
// a real LCM log (lcm::LogFile, the format lcm-logger writes), then damaged the way real logs
// are: a dropped command, a dropped state, a flipped bit in a channel name or a sequence number,
// a corrupt event. read_log must use every complete step and name what is missing and where.
#include <gtest/gtest.h>
#include <unistd.h>
#include <lcm/lcm-cpp.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/record/log_reader.hpp"
#include "feeddrive/reference_block_t.hpp"

namespace feeddrive::record {
namespace {
namespace fs = std::filesystem;

constexpr long kSteps = 4000;
constexpr double kT = 1e-3;

// One logged message: channel and encoded bytes.
struct Msg {
  std::string channel;
  std::vector<std::uint8_t> data;
};

template <typename T>
Msg encode(const std::string& channel, const T& m) {
  Msg out{channel, std::vector<std::uint8_t>(static_cast<std::size_t>(m.getEncodedSize()))};
  m.encode(out.data.data(), 0, static_cast<int>(out.data.size()));
  return out;
}

// The messages of a run in lockstep order: reference blocks of 16 ahead, then per step the
// state (carrying what was applied in the step before) and the command; the end-of-run state.
std::vector<Msg> run_messages(long kSteps = kSteps) {
  std::vector<Msg> out;
  const auto u_of = [](long k) { return 0.1 * std::sin(0.01 * static_cast<double>(k)); };
  for (long k = 0; k <= kSteps; ++k) {
    if (k % 16 == 0 && k < kSteps) {
      reference_block_t b{};
      b.first_seq = k;
      b.count = static_cast<std::int32_t>(std::min<long>(16, kSteps - k));
      for (int i = 0; i < b.count; ++i) {
        reference_t r{};
        r.seq = k + i;
        r.t = static_cast<double>(k + i) * kT;
        r.position = 1e-3 * r.t;
        r.velocity = 1e-3;
        b.refs.push_back(r);
      }
      out.push_back(encode("FD_REF", b));
    }
    drive_state_t s{};
    s.seq = k;
    s.t = static_cast<double>(k) * kT;
    s.steps = kSteps;
    s.end_of_run = k == kSteps;
    s.x_measured = 1e-3 * s.t;
    s.v_measured = 1e-3;
    s.truth.valid = false;
    s.previous.seq = k - 1;
    s.previous.u = k > 0 ? u_of(k - 1) : std::nan("");
    s.previous.forces_valid = false;
    out.push_back(encode("FD_STATE", s));
    if (k < kSteps) {
      control_command_t c{};
      c.seq = k;
      c.t = s.t;
      c.u = c.u_unsaturated = u_of(k);
      c.sliding = c.z_estimate = std::nan("");
      out.push_back(encode("FD_CMD", c));
    }
  }
  return out;
}

std::string write_log(const std::string& name, const std::vector<Msg>& msgs) {
  const fs::path p =
      fs::temp_directory_path() / ("feeddrive_log_gaps_" + std::to_string(::getpid()) + "_" + name + ".lcmlog");
  lcm::LogFile log(p.string(), "w");
  EXPECT_TRUE(log.good());
  std::int64_t t = 1700000000000000;
  for (const Msg& m : msgs) {
    lcm::LogEvent ev{};
    ev.timestamp = t++;
    ev.channel = m.channel;
    ev.datalen = static_cast<std::int32_t>(m.data.size());
    ev.data = const_cast<std::uint8_t*>(m.data.data());
    log.writeEvent(&ev);
  }
  return p.string();
}

// Index of the message on `channel` for step `seq` (the first of its kind).
std::size_t find(const std::vector<Msg>& msgs, const std::string& channel, long seq) {
  for (std::size_t i = 0; i < msgs.size(); ++i) {
    if (msgs[i].channel != channel) continue;
    std::int64_t s = 0;  // every message of ours begins with the 8-byte fingerprint, int64 run_id, int64 seq
    for (int b = 0; b < 8; ++b) s = (s << 8) | msgs[i].data[16 + b];
    if (s == seq) return i;
  }
  ADD_FAILURE() << "no " << channel << " " << seq;
  return 0;
}

// read_log with the rows collected.
struct Read {
  LogConversion c;
  std::vector<sim::Record> rows;
};
Read read_all(const std::string& path) {
  Read r;
  r.c = read_log(path, "FD", [&](const sim::Record& q) { r.rows.push_back(q); });
  return r;
}

// The live attached monitor (MonitorNode --attach) on a run it joined mid-way, fed in arrival
// order: a step whose messages are lost for good is recorded without its command if only that
// is missing (the applied u is in the next state), or skipped as a gap to the next state; a step
// with nothing after it yet is late, not lost, and is not skipped.
TEST(LiveAttach, LostStepsAreSkippedAsGapsAndLateOnesAreNot) {
  auto msgs = run_messages();
  msgs.erase(msgs.begin() + static_cast<long>(find(msgs, "FD_CMD", 2000)));
  msgs.erase(msgs.begin() + static_cast<long>(find(msgs, "FD_STATE", 3000)));
  Recorder rec(true);  // attach, live
  std::vector<sim::Record> rows;
  const auto sink = [&](const sim::Record& r) { rows.push_back(r); };
  const auto feed = [&](const Msg& m) {
    const auto* d = m.data.data();
    const int n = static_cast<int>(m.data.size());
    if (m.channel == "FD_STATE") {
      drive_state_t x;
      ASSERT_GE(x.decode(d, 0, n), 0);
      rec.on_state(x, 0);
    } else if (m.channel == "FD_CMD") {
      control_command_t x;
      ASSERT_GE(x.decode(d, 0, n), 0);
      rec.on_command(x, 0);
    } else {
      reference_block_t x;
      ASSERT_GE(x.decode(d, 0, n), 0);
      for (const reference_t& r : x.refs) rec.on_reference(r, 0);
    }
  };
  // Joins after the state of step 100: its first block of references is the one of step 112.
  const std::size_t join = find(msgs, "FD_STATE", 100);
  const std::size_t before_3000 = find(msgs, "FD_STATE", 2999) + 1;
  for (std::size_t i = join; i < before_3000; ++i) feed(msgs[i]);
  rec.flush(sink);
  ASSERT_TRUE(rec.started());
  ASSERT_FALSE(rows.empty());
  EXPECT_DOUBLE_EQ(rows.front().t, 112 * kT) << "the first step with both its state and its reference";
  EXPECT_EQ(rec.next(), 2000) << "waits for command 2000";
  rec.skip_lost(sink);  // command 2000 is lost: the row is written, diagnostics NaN
  EXPECT_EQ(rec.next(), 2999) << "step 2999 needs state 3000, not sent yet";
  EXPECT_TRUE(std::isnan(rows[2000 - 112].u_unsaturated));
  EXPECT_DOUBLE_EQ(rows[2000 - 112].u, 0.1 * std::sin(20.0)) << "the applied input, from state 2001";
  EXPECT_EQ(rec.skip_lost(sink), 0u) << "nothing after step 2999 yet: late, not lost";
  EXPECT_TRUE(rec.gaps().empty());
  for (std::size_t i = before_3000; i < msgs.size(); ++i) feed(msgs[i]);
  EXPECT_EQ(rec.flush(sink), 0u) << "state 3000 never came";
  rec.skip_lost(sink);
  ASSERT_EQ(rec.gaps().size(), 1u);
  EXPECT_EQ(rec.gaps()[0].first, 2999);
  EXPECT_EQ(rec.gaps()[0].last, 3000);
  EXPECT_EQ(rec.gaps()[0].why, "no state 3000 from the plant");
  EXPECT_TRUE(rec.complete());
  EXPECT_EQ(rows.size(), static_cast<std::size_t>(kSteps - 112 - 2));
  EXPECT_DOUBLE_EQ(rows.back().t, (kSteps - 1) * kT);
}

TEST(LogGaps, CompleteLogHasEveryStepAndNoGap) {
  const auto [c, rows] = read_all(write_log("complete", run_messages()));
  EXPECT_EQ(rows.size(), static_cast<std::size_t>(kSteps));
  EXPECT_TRUE(c.recorder.gaps().empty());
  EXPECT_EQ(c.recorder.commandless_rows(), 0);
}

TEST(LogGaps, ShortLogReadBeforeAnyPeriodicFlushHasEveryStep) {
  // read_log flushes rows every 4096 events; a run of 1,000 steps (about 2,060 events) is only
  // flushed at the end, and must still start at its lowest logged step.
  const auto [c, rows] = read_all(write_log("short", run_messages(1000)));
  EXPECT_EQ(rows.size(), 1000u);
  EXPECT_TRUE(c.recorder.gaps().empty());
}

TEST(LogGaps, DroppedCommandCostsNoStep) {
  // The case: one FD_CMD dropped at step 3000 of 4000 used to cut the record to 3000.
  auto msgs = run_messages();
  msgs.erase(msgs.begin() + static_cast<long>(find(msgs, "FD_CMD", 3000)));
  const auto [c, rows] = read_all(write_log("no_cmd", msgs));
  ASSERT_EQ(rows.size(), static_cast<std::size_t>(kSteps));
  EXPECT_TRUE(c.recorder.gaps().empty());
  EXPECT_EQ(c.recorder.commandless_rows(), 1);
  // The applied input comes from state 3001, so the row is exact; only diagnostics are NaN.
  const auto& row = rows[3000];
  EXPECT_DOUBLE_EQ(row.u, 0.1 * std::sin(30.0));
  EXPECT_TRUE(std::isnan(row.u_unsaturated));
}

TEST(LogGaps, DroppedStateIsAGapNamedWithItsSteps) {
  auto msgs = run_messages();
  msgs.erase(msgs.begin() + static_cast<long>(find(msgs, "FD_STATE", 3000)));
  const auto [c, rows] = read_all(write_log("no_state", msgs));
  // Step 2999 lacks the input applied during it (in state 3000), step 3000 its position.
  ASSERT_EQ(c.recorder.gaps().size(), 1u);
  EXPECT_EQ(c.recorder.gaps()[0].first, 2999);
  EXPECT_EQ(c.recorder.gaps()[0].last, 3000);
  EXPECT_EQ(rows.size(), static_cast<std::size_t>(kSteps - 2));
  EXPECT_EQ(describe_gaps(c.recorder.gaps()), "2 steps missing: 2999-3000 (no state 3000 from the plant)");
  // Rows continue after the gap.
  EXPECT_DOUBLE_EQ(rows.back().t, static_cast<double>(kSteps - 1) * kT);
}

TEST(LogGaps, FlippedBitInAChannelNameIsAGapNotACut) {
  auto msgs = run_messages();
  msgs[find(msgs, "FD_STATE", 1000)].channel[3] ^= 0x01;  // "FD_RTATE": another channel
  const auto [c, rows] = read_all(write_log("flip_channel", msgs));
  EXPECT_EQ(c.foreign_events, 1);
  EXPECT_EQ(c.recorder.missing_steps(), 2);
  EXPECT_EQ(rows.size(), static_cast<std::size_t>(kSteps - 2));
}

TEST(LogGaps, FlippedBitInASequenceNumberIsAGapNotACut) {
  auto msgs = run_messages();
  msgs[find(msgs, "FD_STATE", 2000)].data[16 + 2] ^= 0x10;  // seq 2000 -> 2000 + 2^44
  const auto [c, rows] = read_all(write_log("flip_seq", msgs));
  EXPECT_EQ(c.recorder.missing_steps(), 2);
  EXPECT_EQ(rows.size(), static_cast<std::size_t>(kSteps - 2));
  ASSERT_EQ(c.recorder.gaps().size(), 1u);
  EXPECT_EQ(c.recorder.gaps()[0].first, 1999);
}

TEST(LogGaps, OneCorruptStepCountCannotMoveTheEnd) {
  auto msgs = run_messages();
  msgs[find(msgs, "FD_STATE", kSteps)].data[8 + 8 + 8 + 8 + 7] ^= 0x40;  // the end state's `steps`
  const auto [c, rows] = read_all(write_log("flip_steps", msgs));
  EXPECT_EQ(c.recorder.steps(), kSteps);
  EXPECT_EQ(rows.size(), static_cast<std::size_t>(kSteps));
}

TEST(LogGaps, LogEndingEarlyReportsTheRest) {
  auto msgs = run_messages();
  msgs.resize(find(msgs, "FD_STATE", 3500));
  const auto [c, rows] = read_all(write_log("short", msgs));
  EXPECT_EQ(rows.size(), 3499u);
  ASSERT_EQ(c.recorder.gaps().size(), 1u);
  EXPECT_EQ(c.recorder.gaps()[0].first, 3499);
  EXPECT_EQ(c.recorder.gaps()[0].last, kSteps - 1);
}

TEST(LogGaps, LastEventCutShortEndsTheLogAndIsReported) {
  // A logger killed (or out of disk) mid-write leaves its last event incomplete. The steps before
  // it are used; the cut event is counted with its offset; the steps after are the end gap.
  auto msgs = run_messages();
  msgs.resize(find(msgs, "FD_STATE", 3500) + 1);  // ends with the state of step 3500
  const std::string path = write_log("cut", msgs);
  const auto full = fs::file_size(path);
  std::size_t last = 0;  // where the last event begins
  for (std::size_t i = 0; i + 1 < msgs.size(); ++i) last += 28 + msgs[i].channel.size() + msgs[i].data.size();
  for (const std::uintmax_t keep : {full - 5, static_cast<std::uintmax_t>(last + 30),
                                    static_cast<std::uintmax_t>(last + 10), static_cast<std::uintmax_t>(last + 2)}) {
    SCOPED_TRACE(keep);
    fs::resize_file(path, keep);
    const auto [c, rows] = read_all(path);
    EXPECT_EQ(c.cut_bytes, static_cast<std::int64_t>(keep - last));
    EXPECT_EQ(c.cut_offset, static_cast<std::int64_t>(last));
    EXPECT_NE(describe_cut(c).find("byte " + std::to_string(last)), std::string::npos) << describe_cut(c);
    EXPECT_EQ(rows.size(), 3499u);  // step 3499 waits for the state of 3500, which was cut
    ASSERT_EQ(c.recorder.gaps().size(), 1u);
    EXPECT_EQ(c.recorder.gaps()[0].first, 3499);
    EXPECT_EQ(c.recorder.gaps()[0].last, kSteps - 1);
  }
  // What is left is not the start of an event: corrupt, named with its offset.
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<long>(last));
    f.put('\x55');
  }
  EXPECT_THROW(read_all(path), std::invalid_argument);
  // An intact log has nothing cut.
  const auto whole = read_all(write_log("uncut", run_messages(100)));
  EXPECT_EQ(whole.c.cut_bytes, 0);
  EXPECT_EQ(describe_cut(whole.c), "");
}

TEST(LogGaps, NonFiniteValuesAreDroppedAndCounted) {
  auto msgs = run_messages();
  drive_state_t s;
  Msg& m = msgs[find(msgs, "FD_STATE", 100)];
  s.decode(m.data.data(), 0, static_cast<int>(m.data.size()));
  s.x_measured = std::numeric_limits<double>::infinity();
  m = encode("FD_STATE", s);
  const auto [c, rows] = read_all(write_log("inf", msgs));
  EXPECT_EQ(c.non_finite, 1);
  EXPECT_EQ(c.recorder.missing_steps(), 2);
  for (const auto& r : rows) ASSERT_TRUE(std::isfinite(r.x_measured));
}

TEST(LogGaps, CorruptEventNamesItsByteOffset) {
  const auto msgs = run_messages();
  const std::string path = write_log("corrupt", msgs);
  // The sync word of event 5 (0-based): 28-byte header + channel + payload per event.
  std::size_t offset = 0;
  for (int i = 0; i < 5; ++i) offset += 28 + msgs[i].channel.size() + msgs[i].data.size();
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<long>(offset));
    f.put('\x55');
  }
  try {
    read_all(path);
    FAIL() << "a corrupt log was read";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("corrupt LCM log after event"), std::string::npos) << msg;
    EXPECT_NE(msg.find("bad sync word at byte " + std::to_string(offset) + " of "), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos);
  }
}

}  // namespace
}  // namespace feeddrive::record
