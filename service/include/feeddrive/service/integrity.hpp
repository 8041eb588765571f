#pragma once
// Message integrity of the bus (docs/security.md): run identity, conflict detection and
// optional authentication. Pure logic, no LCM: bus.hpp and the nodes use it.
//
// * Run identity: every message carries run_id; a process handles only its run's messages
//   and counts the others as foreign (another run on the same group, a replayed log).
// * Conflicts: a StepLedger remembers, per step, the message a node received; a second
//   message for the same step is either identical (a harmless re-publication after a loss) or
//   a conflict, named by the fields that differ.
// * Authentication (optional, --key FILE): every top-level message ends with
//   `int16_t mac_size; byte mac[mac_size]`. A signed message has mac_size = 32 and
//       mac = HMAC-SHA256(key, channel || 0x00 || E)
//   where E is the message's LCM encoding up to (not including) mac_size: the 8-byte type
//   fingerprint, run_id, the step number and every other field. HMAC: RFC 2104, SHA-256:
//   FIPS 180-4; computed with OpenSSL's libcrypto (EVP_MAC "HMAC").

#include <openssl/types.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "feeddrive/common/fields.hpp"
#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/reference_t.hpp"

namespace feeddrive::service {

/// What a node does with a conflict (--on-conflict).
enum class ConflictPolicy {
  kFail,       ///< default: the run fails with one line naming channel, step and fields
  kKeepFirst,  ///< keep the first message, drop the second; counted and logged each time
};
/// The names of --on-conflict (fields::enum_name, enum_from_name, enum_choices).
inline const std::vector<std::pair<ConflictPolicy, const char*>>& enum_names(ConflictPolicy) {
  static const std::vector<std::pair<ConflictPolicy, const char*>> k{{ConflictPolicy::kFail, "fail"},
                                                                     {ConflictPolicy::kKeepFirst, "keep-first"}};
  return k;
}

/// The fields of two messages for the same step that differ, comma-separated in declaration
/// order ("u, u_unsaturated"); "" when identical. Doubles compare bit for bit (a re-published
/// NaN equals itself). run_id and mac are not compared (they are checked before).
std::string differing_fields(const control_command_t& a, const control_command_t& b);
std::string differing_fields(const drive_state_t& a, const drive_state_t& b);
std::string differing_fields(const reference_t& a, const reference_t& b);

/// The message each of the last `capacity` steps arrived with (a ring indexed by step; an
/// older step's slot is reused). O(1) per message, no allocation after construction.
template <typename T>
class StepLedger {
 public:
  enum class Seen { kNew, kSame, kConflict };
  /// capacity: rounded up to a power of two.
  explicit StepLedger(std::size_t capacity = 8192) {
    std::size_t n = 1;
    while (n < capacity) n <<= 1;
    slots_.resize(n);
    mask_ = n - 1;
  }
  /// Records `item` as step seq's, or compares it with the one recorded: kSame if identical,
  /// kConflict (and the differing fields in *diff) if not. The first one stays recorded.
  Seen admit(std::int64_t seq, const T& item, std::string* diff = nullptr) {
    Slot& s = slots_[static_cast<std::uint64_t>(seq) & mask_];
    if (!s.used || s.seq != seq) {
      s.used = true;
      s.seq = seq;
      s.item = item;
      return Seen::kNew;
    }
    std::string d = differing_fields(s.item, item);
    if (d.empty()) return Seen::kSame;
    if (diff) *diff = std::move(d);
    return Seen::kConflict;
  }

 private:
  struct Slot {
    bool used{false};
    std::int64_t seq{0};
    T item{};
  };
  std::vector<Slot> slots_;
  std::size_t mask_{0};
};

/// A fresh run identity: a uniformly random number in 1 .. 2^53-1 (std::random_device), exact
/// in a double, so bindings without 64-bit integers (Lua 5.2) carry it unchanged.
std::int64_t draw_run_id();

/// Under --key, the run id on the wire: a run's given identity R (--run-id, or drawn) bound to
/// the nonce N the plant draws at its start,
///     keyed_run_id(R, N) = 1 + (splitmix64(R xor splitmix64(N)) mod (2^53 - 1)),
/// so a log of an earlier run with the same --run-id (another nonce) is another run's: foreign.
/// splitmix64: Steele, Lea and Flood, "Fast splittable pseudorandom number generators" (2014).
/// N = 0 (no nonce: no key) gives R itself.
std::int64_t keyed_run_id(std::int64_t run_id, std::int64_t nonce);

/// HMAC-SHA256(key, data) (RFC 2104 over FIPS 180-4), for tests and tools.
std::array<std::uint8_t, 32> hmac_sha256(const std::string& key, const std::uint8_t* data, std::size_t size);

/// Reads a key file for --key: a regular file, owned by this user, not readable or writable by
/// group or others (mode 0600 or 0400), of 16..4096 bytes; the key is its bytes. Throws
/// std::invalid_argument with one line naming the file and what is wrong.
std::string read_key_file(const std::string& path);

/// Hex SHA-256 of `bytes` (64 lower-case digits): run_info_t.scenario_hash of the scenario file.
std::string sha256_hex(const std::string& bytes);

/// Signs and verifies messages with one key (see the top of this file). Keeps a keyed OpenSSL
/// context, so a message costs one HMAC, not a key setup.
class MessageAuth {
 public:
  static constexpr std::size_t kMacSize = 32;
  /// Bytes of the trailer of a signed message: int16 mac_size (big-endian 32) and the mac.
  static constexpr std::size_t kTrailer = 2 + kMacSize;
  explicit MessageAuth(const std::string& key);
  ~MessageAuth();
  MessageAuth(const MessageAuth&) = delete;
  MessageAuth& operator=(const MessageAuth&) = delete;

  /// data[0, size) is a message's encoding with mac_size = 32 and 32 bytes of room for the mac
  /// at its end: writes the mac there.
  void sign(const std::string& channel, std::uint8_t* data, std::size_t size) const;
  /// True if data[0, size) ends with mac_size = 32 and the right mac for `channel`.
  bool verify(const std::string& channel, const std::uint8_t* data, std::size_t size) const;

 private:
  void mac(const std::string& channel, const std::uint8_t* body, std::size_t size, std::uint8_t* out) const;
  EVP_MAC* mac_alg_{nullptr};
  EVP_MAC_CTX* ctx_{nullptr};
};

}  // namespace feeddrive::service
