#pragma once
// The channel names of one run, in one place: the nodes publish and subscribe on them
// (service/bus.hpp), the monitor and feeddrive-log2csv read them from a bus or a log
// (docs/lcm-contract.md, Channels).

#include <string>

namespace feeddrive::record {

/// Channel names of one run: <prefix>_STATE, _CMD, _REF, _STATUS, _RESEND, _SUMMARY, _INFO.
struct Channels {
  explicit Channels(const std::string& prefix);
  std::string state, command, reference, status, resend, summary, info;
};

}  // namespace feeddrive::record
