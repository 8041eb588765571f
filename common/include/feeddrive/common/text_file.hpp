#pragma once
// The one reader of small text files (scenario and study YAML): bounded in size and
// interruptible, so a wrong path (/dev/zero, a log, a disk image) is refused in one line instead
// of filling the memory. Header-only.

#include <cstddef>
#include <fstream>
#include <stdexcept>
#include <string>

#include "feeddrive/common/interrupt.hpp"

namespace feeddrive::text {

/// A scenario or study file is at most 1 MiB (docs/scenario.md, Limits): the largest shipped one
/// is under 4 kB.
inline constexpr std::size_t kMaxTextFileBytes = std::size_t{1} << 20;

/// The bytes of the file `path`, read in 64 kB chunks (Ctrl-C is polled between them: it throws
/// interrupt::Interrupted). Throws Error("PATH: cannot read the WHAT") or Error("PATH: the WHAT is
/// larger than ... bytes ..."), one line; Error is the caller's exception type (ScenarioError,
/// StudyError), constructible from a std::string.
template <typename Error>
std::string read_text_file(const std::string& path, const std::string& what, std::size_t max_bytes = kMaxTextFileBytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    interrupt::check();  // a Ctrl-C while open() waited (a FIFO) is an interrupt, not bad input
    throw Error(path + ": cannot read the " + what);
  }
  std::string text;
  static constexpr std::size_t kChunk = 1 << 16;
  char buf[kChunk];
  while (in) {
    interrupt::check();
    in.read(buf, kChunk);
    text.append(buf, static_cast<std::size_t>(in.gcount()));
    if (text.size() > max_bytes)
      throw Error(path + ": the " + what + " is larger than " + std::to_string(max_bytes) +
                  " bytes, the limit of a scenario or study file (docs/scenario.md, Limits); is it the right file?");
  }
  if (in.bad()) {
    interrupt::check();
    throw Error(path + ": cannot read the " + what);
  }
  return text;
}

}  // namespace feeddrive::text
