#include "feeddrive/service/contract.hpp"

#include <cstring>

namespace feeddrive::service {
namespace {

// LCM fingerprints (the first 8 bytes of an encoded message, big-endian) of the types of earlier
// contracts, computed with lcm-gen from lcmtypes/ at the commits of each version (git history:
// 96fcf52 for 1; 3825bbe, b527dd6 and bf315dd for 2; fad0b3a for 3). Types that did not change are
// not listed: a version 3 participant's heartbeat (process_status_t, unchanged in 4) decodes, and
// its contract_version 3 names it (the monitor's check_peer_status).
struct Known {
  std::uint64_t hash;
  int version;
  const char* type;
  const char* when;
};
constexpr Known kOlder[] = {
    {0x0d5a8c3da348cf7dULL, 1, "process_status_t", "23 November 2026"},
    {0x41d22097f51277acULL, 1, "control_command_t", "23 November 2026"},
    {0x9b02ea8ce8073b11ULL, 1, "drive_state_t", "23 November 2026"},
    {0x095f1f117db13e68ULL, 1, "reference_block_t", "23 November 2026"},
    {0x07d6b2c45ee7cd1eULL, 1, "resend_request_t", "23 November 2026"},
    {0xa123f09daef14f3cULL, 1, "run_info_t", "23 November 2026"},
    {0x82c6d4827f2f3fedULL, 2, "process_status_t", "24 November 2026"},
    {0x10e6db5df442da54ULL, 2, "drive_state_t", "24 November 2026, before its overrun fields"},
    {0xa573df60dff0e8e1ULL, 2, "run_info_t", "24 November 2026"},
    {0x2a2e53f13bd0f348ULL, 3, "run_info_t", "26 November 2026, with its drive's parameters as fields"},
};

std::uint64_t be64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  return v;
}

// A string at `off`: int32 length (with the NUL), the bytes, NUL. "" when out of bounds.
std::string lcm_string(const std::uint8_t* d, std::size_t n, std::size_t off) {
  if (off + 4 > n) return "";
  const std::uint32_t len = (std::uint32_t{d[off]} << 24) | (std::uint32_t{d[off + 1]} << 16) |
                            (std::uint32_t{d[off + 2]} << 8) | std::uint32_t{d[off + 3]};
  if (len == 0 || len > 64 || off + 4 + len > n) return "";
  std::string s(reinterpret_cast<const char*>(d + off + 4), len - 1);
  for (char c : s)
    if (c < 0x20 || c > 0x7e) return "";
  return s;
}

}  // namespace

std::string publisher_of(const Channels& ch, std::string_view channel) {
  if (channel == ch.state) return "plant";
  if (channel == ch.command) return "controller";
  if (channel == ch.reference) return "trajectory";
  return "";
}

std::string heartbeat_role(const std::uint8_t* data, std::size_t size) {
  // process_status_t of contracts 3 and 4: fingerprint, run_id, utime, run_nonce, role.
  return lcm_string(data, size, 8 + 8 + 8 + 8);
}

std::optional<OlderSender> older_contract(const Channels& ch, std::string_view channel, const std::uint8_t* data,
                                          std::size_t size) {
  if (size < 8) return std::nullopt;
  const std::uint64_t h = be64(data);
  for (const Known& k : kOlder) {
    if (k.hash != h) continue;
    OlderSender s{k.version, publisher_of(ch, channel), std::string(k.type) + " of " + k.when};
    if (std::strcmp(k.type, "process_status_t") == 0)
      s.role = lcm_string(data, size, k.version == 1 ? 8 + 8 : 8 + 8 + 8);  // version 1: no run_id before utime
    return s;
  }
  return std::nullopt;
}

std::string describe_older(const OlderSender& s, std::string_view channel) {
  const std::string who = s.role.empty() ? "a participant" : "the " + s.role;
  return who + " speaks contract version " + std::to_string(s.version) + " (a " + s.type + " on " +
         std::string(channel) + "); this run speaks " + std::to_string(kContractVersion) +
         ": rebuild it with this feeddrive's lcmtypes/" +
         (s.version < 2 ? " and stamp run_info_t.run_id on every message" : "") + " (docs/lcm-contract.md, Versions)";
}

}  // namespace feeddrive::service
