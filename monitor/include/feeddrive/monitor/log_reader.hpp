#pragma once
// Reads an LCM log written by the stock lcm-logger and rebuilds the run's rows with the same
// Recorder as the live monitor, so the converted timeseries.csv equals the monitor's.

#include <string>

#include "feeddrive/monitor/recorder.hpp"

namespace feeddrive::monitor {

struct LogConversion {
  Recorder recorder{true, true};        ///< rows found (attach mode: from the first state logged)
  long events{0};                 ///< events read
  long foreign_events{0};         ///< events on channels of other prefixes
  long undecodable{0};            ///< events on our channels that are not our type
};

/// Converts the events on <prefix>_STATE/_REF/_CMD of log `path`, handing each row to `sink` in
/// step order as soon as it is complete. Throws std::invalid_argument naming the file when it
/// cannot be opened or is corrupt (with the event number and offset).
LogConversion read_log(const std::string& path, const std::string& prefix, const sim::RecordSink& sink);

}  // namespace feeddrive::monitor
