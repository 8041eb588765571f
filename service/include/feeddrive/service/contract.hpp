#pragma once
// The version of the message contract (lcmtypes/) and how a participant of another version is
// named (docs/lcm-contract.md, "Versions"). Every heartbeat (process_status_t) and run_info_t
// carries the version; a message of an older contract does not decode as this one's type (its
// LCM fingerprint differs), so older versions are recognised by their fingerprints, kept here.
//
// History:
//   1  (23 November 2026)  no run_id, no mac
//   2  (24 November 2026)  run_id and mac in every top-level message, run_info_t
//   3  (26 November 2026)  contract_version in process_status_t and run_info_t; run_info_t carries
//                          the protocol's options, the initial state, the sensor model, the
//                          scenario's hash and the current step
//   4  (27 November 2026)  run_info_t.plant: the drive's parameters as (key, value) entries
//                          (parameter_t), the plant's one list walked, in place of a hand-written
//                          set of fields (which missed stribeck_exponent)

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "feeddrive/service/bus.hpp"

namespace feeddrive::service {

inline constexpr std::int32_t kContractVersion = 4;

/// The role that publishes on `channel` of a run: <prefix>_STATE the plant, _CMD the controller,
/// _REF the trajectory; "" for the others (every role, or a tool).
std::string publisher_of(const Channels& ch, std::string_view channel);

/// A message that arrived on `channel` and is not of an older contract: nullopt. Otherwise what
/// is known about its sender: the contract version, and its role (from the channel, or from an
/// older heartbeat's role field) or "".
struct OlderSender {
  int version{0};
  std::string role;
  std::string type;
};
std::optional<OlderSender> older_contract(const Channels& ch, std::string_view channel, const std::uint8_t* data,
                                          std::size_t size);

/// One line: "the controller speaks contract version 2 (a control_command_t of 24 November 2026)
/// on FD_CMD; this run speaks 4: update it to the lcmtypes/ of this feeddrive (docs/lcm-contract.md, Versions)".
std::string describe_older(const OlderSender& s, std::string_view channel);

/// The role field of a heartbeat that would not be admitted (another run, no valid mac), read
/// without trusting it beyond its bounds: "" when it cannot be read.
std::string heartbeat_role(const std::uint8_t* data, std::size_t size);

}  // namespace feeddrive::service
