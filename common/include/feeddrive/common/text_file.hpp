#pragma once
// The one reader of small text files (scenario and study YAML): bounded in size, so a wrong path (/dev/zero, a log, a
// disk image) is refused in one line instead of filling the memory. Header-only.

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstring>
#include <stdexcept>
#include <string>

namespace feeddrive::text {

/// A scenario or study file is at most 1 MiB (docs/scenario.md, Limits): the largest shipped one
/// is under 4 kB.
inline constexpr std::size_t kMaxTextFileBytes = std::size_t{1} << 20;

/// What kind of file `mode` is, when it is not a regular file ("a FIFO", "a folder", ...).
inline std::string non_regular_kind(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

/// Opens `path` for reading without blocking (a FIFO would block a plain open() until a writer
/// comes) and returns the descriptor of a regular file. Throws Error("PATH: cannot read the WHAT
/// (...)") or Error("PATH: the WHAT is a FIFO, not a regular file"), one line.
template <typename Error>
int open_regular_file(const std::string& path, const std::string& what) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw Error(path + ": cannot read the " + what + " (" + std::strerror(errno) + ")");
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    const std::string kind = non_regular_kind(st.st_mode);
    ::close(fd);
    throw Error(path + ": the " + what + " is " + kind + ", not a regular file");
  }
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  return fd;
}

/// The bytes of the file `path`, read in 64 kB chunks (a regular file of at most max_bytes, 1 MB by
/// default: read in milliseconds, so Ctrl-C is seen by the caller's next poll). Throws Error("PATH: cannot read the
/// WHAT"), Error("PATH: the WHAT is a FIFO, not a regular file") or Error("PATH: the WHAT is larger than ... bytes
/// ..."), one line; Error is the caller's exception type (ScenarioError, StudyError), constructible from a std::string.
/// Never blocks in open().
template <typename Error>
std::string read_text_file(const std::string& path, const std::string& what,
                           std::size_t max_bytes = kMaxTextFileBytes) {
  const int fd = open_regular_file<Error>(path, what);
  std::string text;
  static constexpr std::size_t kChunk = 1 << 16;
  char buf[kChunk];
  for (;;) {
    const ssize_t n = ::read(fd, buf, kChunk);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      throw Error(path + ": cannot read the " + what + " (" + std::strerror(err) + ")");
    }
    if (n == 0) break;
    text.append(buf, static_cast<std::size_t>(n));
    if (text.size() > max_bytes) {
      ::close(fd);
      throw Error(path + ": the " + what + " is larger than " + std::to_string(max_bytes) +
                  " bytes, the limit of a scenario or study file (docs/scenario.md, Limits); is it the right file?");
    }
  }
  ::close(fd);
  return text;
}

}  // namespace feeddrive::text
