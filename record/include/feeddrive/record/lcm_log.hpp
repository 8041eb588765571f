#pragma once
// The LCM log file format, in one place: the event header that feeddrive-log2csv reads
// (log_reader.cpp) and feeddrive-monitor --lcm-log writes (LcmLogWriter).
//
// Format (LCM's lcm/eventlog.c, 1.3; the same files lcm-logger writes and lcm-logplayer,
// lcm-spy's log viewer and lcm.EventLog read): a sequence of events, each a big-endian header
//   uint32 sync = 0xEDA1DA01, int64 event number, int64 timestamp [us since the epoch],
//   int32 channel length, int32 data length,
// followed by the channel name (no NUL) and the payload (the encoded message).

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace feeddrive::record {

constexpr std::uint32_t kLcmLogSync = 0xEDA1DA01u;
constexpr std::size_t kLcmLogHeaderSize = 28;
/// The first four bytes of every LCM log file (the sync word, big-endian): an existing file that
/// does not start with them is not an LCM log and is never overwritten by --lcm-log.
inline const std::string kLcmLogMagic{"\xED\xA1\xDA\x01", 4};

struct LcmLogHeader {
  std::uint32_t sync{kLcmLogSync};
  std::int64_t event_number{0};
  std::int64_t timestamp{0};  ///< [us since the Unix epoch]
  std::int32_t channel_length{0};
  std::int32_t data_length{0};
};

/// Decodes the 28 header bytes at p (no validation: the reader checks sync and lengths).
LcmLogHeader decode_lcm_log_header(const std::uint8_t* p);
/// Encodes h into the 28 bytes at p.
void encode_lcm_log_header(const LcmLogHeader& h, std::uint8_t* p);

/// Writes an LCM log, event by event, as lcm-logger does (event numbers from 0). Buffered;
/// close() flushes and reports a write error. Throws std::runtime_error naming the file.
class LcmLogWriter {
 public:
  /// Creates (truncates) `path`.
  explicit LcmLogWriter(const std::string& path);
  ~LcmLogWriter();
  LcmLogWriter(const LcmLogWriter&) = delete;
  LcmLogWriter& operator=(const LcmLogWriter&) = delete;

  void write(std::string_view channel, const std::uint8_t* data, std::size_t size, std::int64_t utime);
  /// Flushes and closes; throws on a write error. Idempotent.
  void close();
  std::int64_t events() const { return events_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::FILE* f_{nullptr};
  std::int64_t events_{0};
  bool failed_{false};
};

}  // namespace feeddrive::record
