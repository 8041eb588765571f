#pragma once
// Text checks shared by the scenario loader and the plot writer: well-formed UTF-8 (RFC 3629,
// Table 3-7 of the Unicode Standard: no overlong forms, no surrogates, at most U+10FFFF); and the
// one split of a text at a separator (dotted keys, ranges). Header-only.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace feeddrive::text {

/// The parts of `s` between the separators ("plant.friction" at '.' -> plant, friction; "" -> one
/// empty part).
inline std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  for (std::size_t b = 0;;) {
    const std::size_t e = s.find(sep, b);
    parts.push_back(s.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (e == std::string::npos) return parts;
    b = e + 1;
  }
}

/// Length of the well-formed UTF-8 sequence at s[i] encoding a character from U+00A0 up (so no
/// C1 control character), or 0 (ASCII, a malformed sequence, or one cut by the end of s).
inline std::size_t utf8_char(std::string_view s, std::size_t i) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[i + k]); };
  const unsigned char c = b(0);
  std::size_t n = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // allowed range of the second byte
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2;
    if (c == 0xC2) lo = 0xA0;  // U+0080..U+009F are C1 control characters
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3;
    if (c == 0xE0) lo = 0xA0;  // overlong
    if (c == 0xED) hi = 0x9F;  // surrogates
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4;
    if (c == 0xF0) lo = 0x90;  // overlong
    if (c == 0xF4) hi = 0x8F;  // above U+10FFFF
  } else {
    return 0;
  }
  if (i + n > s.size()) return 0;
  if (b(1) < lo || b(1) > hi) return 0;
  for (std::size_t k = 2; k < n; ++k)
    if (b(k) < 0x80 || b(k) > 0xBF) return 0;
  return n;
}

/// Byte offset of the first byte of `s` that is neither printable ASCII (0x20..0x7E) nor part of
/// a well-formed UTF-8 character from U+00A0 up; s.size() if there is none.
inline std::size_t first_unprintable(std::string_view s) {
  for (std::size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c >= 0x20 && c < 0x7F) {
      ++i;
    } else if (const std::size_t n = utf8_char(s, i); n > 0) {
      i += n;
    } else {
      return i;
    }
  }
  return s.size();
}

}  // namespace feeddrive::text
