#include "feeddrive/output/csv.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <stdexcept>

namespace feeddrive::output {

namespace {
constexpr std::size_t kBufferBytes = std::size_t{1} << 20;
}

char* format_number(char* first, double v) {
  // to_chars never fails with kMaxNumberChars of room: the shortest form of any double fits.
  return std::to_chars(first, first + kMaxNumberChars, v).ptr;
}

std::string number_text(double v) {
  char buf[kMaxNumberChars];
  return std::string(buf, format_number(buf, v));
}

CsvWriter::CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns)
    : path_(path), buf_(kBufferBytes) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw std::runtime_error(path.string() + ": cannot open for writing: " + std::strerror(errno));
  std::string header;
  for (std::size_t c = 0; c < columns.size(); ++c) header += (c ? "," : "") + columns[c];
  header += '\n';
  std::memcpy(buf_.data(), header.data(), std::min(header.size(), buf_.size()));
  used_ = std::min(header.size(), buf_.size());
}

CsvWriter::~CsvWriter() {
  if (fd_ >= 0) ::close(fd_);
}

void CsvWriter::row(const double* values, std::size_t n) {
  const std::size_t need = n * (kMaxNumberChars + 1) + 1;
  if (buf_.size() - used_ < need) {
    flush();
    if (buf_.size() < need) buf_.resize(need);
  }
  char* p = buf_.data() + used_;
  for (std::size_t c = 0; c < n; ++c) {
    if (c) *p++ = ',';
    p = format_number(p, values[c]);
  }
  *p++ = '\n';
  used_ = static_cast<std::size_t>(p - buf_.data());
  ++rows_;
}

void CsvWriter::flush() {
  const char* p = buf_.data();
  std::size_t left = used_;
  while (left > 0) {
    const ssize_t w = ::write(fd_, p, left);
    if (w < 0) {
      if (errno == EINTR) continue;  // a signal: the caller polls the interrupt flag
      throw std::runtime_error(path_.string() + ": write failed: " + std::strerror(errno));
    }
    p += w;
    left -= static_cast<std::size_t>(w);
    bytes_ += static_cast<std::uint64_t>(w);
  }
  used_ = 0;
}

void CsvWriter::close() {
  if (fd_ < 0) return;
  flush();
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) throw std::runtime_error(path_.string() + ": write failed: " + std::strerror(errno));
}

}  // namespace feeddrive::output
