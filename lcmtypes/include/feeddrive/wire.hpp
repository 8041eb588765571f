#pragma once
// The one decode of an untrusted LCM message, for every process and tool that reads the bus or
// a log (service::Bus, the monitor, feeddrive-log2csv, the fit's log reader).
//
// lcm-gen's decode sizes an array from the received count before it checks that the bytes are
// there (a reference_block_t with count = 10^7 allocates 560 MB), and throws std::length_error on
// a string of length 0 or a negative count. So the bytes are first walked against the contract's
// bounds (wire_check.hpp, generated from the {max N} and {lo..hi} tags in the .lcm files): the
// size, the fingerprint, each string's length and NUL, each array's count, no trailing bytes.
// Only an encoding that passes is handed to decode, and decode itself runs inside a try. A
// message that fails is not an error of the run: the caller counts it and drops it.

#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>

#include "feeddrive/wire_check.hpp"

namespace feeddrive::wire {

/// `s` cut to at most `max` bytes (the contract's bound of the field it goes into), not inside a
/// UTF-8 sequence. A publisher applies it, so its own messages never break the bounds.
inline std::string fit(const std::string& s, std::size_t max) {
  if (s.size() <= max) return s;
  std::size_t n = max;
  while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;  // s[n] continues a sequence
  return s.substr(0, n);
}

/// Decodes `size` bytes at `data` as Msg into `out`. Returns false, with the reason in *why when
/// given, when the encoding is larger than the contract allows, has another fingerprint, has a
/// field out of its bound, is truncated or longer than its fields, or when decode fails or throws.
/// Allocates at most Check<Msg>::kMaxEncoded bytes' worth of fields.
template <typename Msg>
bool decode_untrusted(const void* data, std::size_t size, Msg& out, std::string* why = nullptr) {
  const auto say = [why](std::string s) {
    if (why != nullptr) *why = std::move(s);
    return false;
  };
  if (size > Check<Msg>::kMaxEncoded)
    return say(std::string(Msg::getTypeName()) + " of " + std::to_string(size) + " bytes, above the contract's " +
               std::to_string(Check<Msg>::kMaxEncoded));
  Cursor c{static_cast<const std::uint8_t*>(data), size, 0, {}};
  std::int64_t hash = 0;
  const std::int64_t want = Msg::getHash();
  if (!c.integer(8, hash, INT64_MIN, INT64_MAX, "fingerprint") || hash != want)
    return say(std::string("not a ") + Msg::getTypeName() + " (another fingerprint)");
  if (!Check<Msg>::body(c)) return say(c.why);
  if (c.pos != size)
    return say(std::string(Msg::getTypeName()) + " with " + std::to_string(size - c.pos) + " trailing bytes");
  try {
    if (out.decode(data, 0, static_cast<int>(size)) != static_cast<int>(size)) return say("decode failed");
  } catch (const std::exception& e) {
    return say(std::string("decode threw: ") + e.what());
  }
  return true;
}

}  // namespace feeddrive::wire
