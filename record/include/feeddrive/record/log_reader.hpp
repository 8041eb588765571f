#pragma once
// Reads an LCM log written by the stock lcm-logger and rebuilds the run's rows with the same
// Recorder as the live monitor, so the converted timeseries.csv equals the monitor's.

#include <string>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/record/recorder.hpp"

namespace feeddrive::record {

struct LogConversion {
  Recorder recorder{true, true};  ///< rows found (attach mode: from the first state logged)
  long events{0};                 ///< events read
  long foreign_events{0};         ///< events on channels of other prefixes
  long undecodable{0};            ///< events on our channels that are not our type
  long non_finite{0};             ///< states or references with a NaN or infinite value (dropped)
  std::int64_t cut_bytes{0};      ///< bytes of a last event cut short (the logger stopped mid-write), ignored
  std::int64_t cut_offset{-1};    ///< where that event began (byte offset), or -1
};

/// One line on a log whose last event was cut short ("" if it was not): where, and how many bytes.
std::string describe_cut(const LogConversion& c);

/// Converts the events on <prefix>_STATE/_REF/_CMD of log `path`, handing each row to `sink` in
/// step order: every step that can be completed, across gaps (Recorder::flush_final with
/// need_reference); the steps that cannot are in recorder.gaps(). A state or reference with a
/// non-finite value is dropped and counted. A last event cut short by the end of the file (a
/// logger killed or out of disk) ends the log: its bytes are counted (cut_bytes), the steps it
/// leaves incomplete are a gap. Throws std::invalid_argument naming the file when it cannot be
/// opened or an event is corrupt (with the event number and byte offset); interrupt::Interrupted
/// when `stop` asks to stop (polled every 1024 events; the default never stops).
LogConversion read_log(const std::string& path, const std::string& prefix, const sim::RecordSink& sink,
                       bool need_reference = true, const interrupt::StopToken& stop = {});

}  // namespace feeddrive::record
