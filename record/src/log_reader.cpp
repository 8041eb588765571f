#include "feeddrive/record/log_reader.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/common/text_file.hpp"
#include "feeddrive/record/channels.hpp"
#include "feeddrive/record/lcm_log.hpp"
#include "feeddrive/reference_block_t.hpp"
#include "feeddrive/wire.hpp"

namespace feeddrive::record {
namespace {

// One event of an LCM log file (the format: lcm_log.hpp). We parse it ourselves rather than with lcm::LogFile
// because liblcm prints its own diagnostics to stderr on a corrupt event, and a bad log must get
// exactly one line that names the event and the byte offset.
struct Event {
  std::int64_t timestamp{0};
  std::string channel;
  std::vector<std::uint8_t> data;
};

constexpr std::int32_t kMaxChannel = 4096;           // far above LCM's 63-character channel limit
constexpr std::int32_t kMaxData = 64 * 1024 * 1024;  // our messages are < 1 KB

class LogParser {
  // A FIFO or a device would block the stream's open(): refused first, in one line.
  static void check_regular(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
      throw std::invalid_argument(path + ": the LCM log is " + text::non_regular_kind(st.st_mode) +
                                  ", not a regular file");
  }

 public:
  explicit LogParser(const std::string& path) : path_(path), in_((check_regular(path), path), std::ios::binary) {
    if (!in_) throw std::invalid_argument(path + ": cannot open the LCM log");
    in_.seekg(0, std::ios::end);
    size_ = static_cast<std::int64_t>(in_.tellg());
    in_.seekg(0);
  }

  // Reads the next event into `ev`; false at the end of the file (also at a last event cut
  // short: see cut_tail()). Throws on corruption.
  bool next(Event& ev, long events_so_far) {
    if (offset_ == size_) return false;
    const std::int64_t left = size_ - offset_;
    std::uint8_t h[kLcmLogHeaderSize];
    if (left < static_cast<std::int64_t>(sizeof h)) {
      // A logger stopped in the middle of writing its last event (killed, disk full): what is
      // left is shorter than a header. If it starts like one, it is that cut event.
      std::uint8_t start[4] = {0, 0, 0, 0};
      in_.read(reinterpret_cast<char*>(start), std::min<std::int64_t>(left, 4));
      const std::uint8_t sync[4] = {0xED, 0xA1, 0xDA, 0x01};
      if (!std::equal(start, start + std::min<std::int64_t>(left, 4), sync))
        corrupt(events_so_far, "truncated event header");
      return cut(left);
    }
    in_.read(reinterpret_cast<char*>(h), sizeof h);
    const LcmLogHeader header = decode_lcm_log_header(h);
    if (header.sync != kLcmLogSync) corrupt(events_so_far, "bad sync word");
    ev.timestamp = header.timestamp;
    const std::int32_t channel_len = header.channel_length;
    const std::int32_t data_len = header.data_length;
    if (channel_len <= 0 || channel_len > kMaxChannel) corrupt(events_so_far, "bad channel length");
    if (data_len < 0 || data_len > kMaxData) corrupt(events_so_far, "bad data length");
    if (left - static_cast<std::int64_t>(sizeof h) < std::int64_t{channel_len} + data_len) {
      // The last event cut short, if it would be one of ours (at most kMaxTail bytes, so less
      // than that is left of the file); a corrupt length in the middle of a log, with more of
      // the log behind it, stays an error.
      if (std::int64_t{channel_len} + data_len + static_cast<std::int64_t>(sizeof h) <= kMaxTail) return cut(left);
      corrupt(events_so_far, "truncated event");
    }
    ev.channel.resize(static_cast<std::size_t>(channel_len));
    in_.read(ev.channel.data(), channel_len);
    ev.data.resize(static_cast<std::size_t>(data_len));
    in_.read(reinterpret_cast<char*>(ev.data.data()), data_len);
    if (!in_) corrupt(events_so_far, "read error");
    offset_ += static_cast<std::int64_t>(sizeof h) + channel_len + data_len;
    return true;
  }

  /// Bytes of a last event cut short that were left unread (0: none), and where it began.
  std::int64_t cut_bytes() const { return cut_bytes_; }
  std::int64_t cut_offset() const { return cut_offset_; }

 private:
  // An LCM event of ours is under 16 kB (a reference block of 256 steps and its mac); the stock
  // logger writes an event in one call, so a cut leaves less than one event.
  static constexpr std::int64_t kMaxTail = 64 * 1024;

  bool cut(std::int64_t left) {
    cut_bytes_ = left;
    cut_offset_ = offset_;
    offset_ = size_;
    return false;
  }

  [[noreturn]] void corrupt(long events, const char* what) const {
    throw std::invalid_argument(path_ + ": corrupt LCM log after event " + std::to_string(events) + " (" + what +
                                " at byte " + std::to_string(offset_) + " of " + std::to_string(size_) + ")");
  }

  std::string path_;
  std::ifstream in_;
  std::int64_t size_{0};
  std::int64_t offset_{0};
  std::int64_t cut_bytes_{0}, cut_offset_{-1};
};

template <typename Msg, typename F>
void decode_into(const Event& ev, LogConversion& out, F&& f) {
  Msg m;
  if (!wire::decode_untrusted(ev.data.data(), ev.data.size(), m)) {  // bounds first, never throws
    ++out.undecodable;
    return;
  }
  f(m, ev.timestamp);
}

// What a row takes from a state and a reference must be finite (a flipped bit in a logged
// double can make it NaN or 1e308-large: dropped and counted, the step becomes a gap).
bool finite_state(const drive_state_t& m) {
  bool ok = std::isfinite(m.t) && std::isfinite(m.x_measured) && std::isfinite(m.v_measured) && m.seq >= 0;
  if (m.truth.valid)
    ok = ok && std::isfinite(m.truth.x) && std::isfinite(m.truth.v) && std::isfinite(m.truth.z) &&
         std::isfinite(m.truth.fg) && std::isfinite(m.truth.i);
  if (m.previous.seq >= 0) ok = ok && std::isfinite(m.previous.u);
  if (m.previous.seq >= 0 && m.previous.forces_valid)
    ok = ok && std::isfinite(m.previous.f_thrust) && std::isfinite(m.previous.f_friction) &&
         std::isfinite(m.previous.f_ripple) && std::isfinite(m.previous.f_grinding);
  return ok;
}

bool finite_reference(const reference_t& m) {
  return std::isfinite(m.t) && std::isfinite(m.position) && std::isfinite(m.velocity) &&
         std::isfinite(m.acceleration) && std::isfinite(m.jerk) && m.seq >= 0;
}

}  // namespace

LogConversion read_log(const std::string& path, const std::string& prefix, const sim::RecordSink& sink,
                       bool need_reference, const interrupt::StopToken& stop) {
  LogParser log(path);
  const Channels ch(prefix);
  LogConversion out;
  Event ev;
  while (log.next(ev, out.events)) {
    if (++out.events % 1024 == 0) stop.check();
    if (ev.channel == ch.state) {
      decode_into<drive_state_t>(ev, out, [&](const drive_state_t& m, std::int64_t t) {
        if (!finite_state(m)) return void(++out.non_finite);
        out.recorder.on_state(m, t);
      });
    } else if (ev.channel == ch.reference) {
      decode_into<reference_block_t>(ev, out, [&](const reference_block_t& b, std::int64_t t) {
        for (const reference_t& m : b.refs) {
          if (!finite_reference(m)) {
            ++out.non_finite;
            continue;
          }
          out.recorder.on_reference(m, t);
        }
      });
    } else if (ev.channel == ch.command) {
      decode_into<control_command_t>(
          ev, out, [&](const control_command_t& m, std::int64_t t) { out.recorder.on_command(m, t); });
    } else {
      ++out.foreign_events;
    }
    if ((out.events & 4095) == 0) {
      out.recorder.flush(sink);  // rows leave as they complete
      stop.check();              // Ctrl-C: unwind (a staged output folder is removed)
    }
  }
  out.recorder.flush_final(sink, need_reference);
  out.cut_bytes = log.cut_bytes();
  out.cut_offset = log.cut_offset();
  return out;
}

std::string describe_cut(const LogConversion& c) {
  if (c.cut_bytes == 0) return "";
  return "the log ends inside an event (byte " + std::to_string(c.cut_offset) + ", its last " +
         std::to_string(c.cut_bytes) + " bytes; the logger stopped mid-write?): that event is ignored";
}

}  // namespace feeddrive::record
