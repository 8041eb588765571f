#pragma once
// A read cursor over an untrusted LCM encoding, used by the generated walks (wire_check.hpp):
// every read is checked against the bytes left, every length and count against its bound from
// the .lcm contract, and nothing is allocated. LCM encodes big-endian; a string is an int32
// length that counts its NUL, then the bytes, the last of them the NUL.

#include <cstddef>
#include <cstdint>
#include <string>

namespace feeddrive::wire {

struct Cursor {
  const std::uint8_t* d;
  std::size_t n;
  std::size_t pos{0};
  std::string why;  ///< the first field out of bounds, e.g. "reference_block_t.count = -1 (bound 1..16)"

  bool fail(const char* field, const std::string& what) {
    why = std::string(field) + " " + what;
    return false;
  }
  bool skip(std::size_t k, const char* field) {
    if (k > n - pos) return fail(field, "truncated (" + std::to_string(n - pos) + " bytes left)");
    pos += k;
    return true;
  }
  /// A big-endian signed integer of `size` bytes, within [lo, hi].
  bool integer(std::size_t size, std::int64_t& v, std::int64_t lo, std::int64_t hi, const char* field) {
    if (size > n - pos) return fail(field, "truncated");
    std::uint64_t u = 0;
    for (std::size_t i = 0; i < size; ++i) u = (u << 8) | d[pos + i];
    const unsigned shift = static_cast<unsigned>(64 - 8 * size);
    v = static_cast<std::int64_t>(u << shift) >> shift;  // sign-extend
    pos += size;
    if (v < lo || v > hi)
      return fail(field, "= " + std::to_string(v) + " (bound " + std::to_string(lo) + ".." + std::to_string(hi) + ")");
    return true;
  }
  /// A string of at most `max` bytes: its length field (NUL included) in [1, max + 1], the bytes
  /// present, the last one NUL.
  bool string(std::size_t max, const char* field) {
    std::int64_t len = 0;
    if (!integer(4, len, 1, static_cast<std::int64_t>(max) + 1, field)) return false;
    const std::size_t k = static_cast<std::size_t>(len);
    if (k > n - pos) return fail(field, "truncated (length " + std::to_string(len) + ")");
    if (d[pos + k - 1] != 0) return fail(field, "has no terminating NUL");
    pos += k;
    return true;
  }
};

}  // namespace feeddrive::wire
