#include "feeddrive/record/lcm_log.hpp"

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace feeddrive::record {
namespace {

std::uint64_t get_be(const std::uint8_t* p, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | p[i];
  return v;
}
void put_be(std::uint64_t v, std::uint8_t* p, int n) {
  for (int i = n - 1; i >= 0; --i) {
    p[i] = static_cast<std::uint8_t>(v & 0xffu);
    v >>= 8;
  }
}

}  // namespace

LcmLogHeader decode_lcm_log_header(const std::uint8_t* p) {
  LcmLogHeader h;
  h.sync = static_cast<std::uint32_t>(get_be(p, 4));
  h.event_number = static_cast<std::int64_t>(get_be(p + 4, 8));
  h.timestamp = static_cast<std::int64_t>(get_be(p + 12, 8));
  h.channel_length = static_cast<std::int32_t>(get_be(p + 20, 4));
  h.data_length = static_cast<std::int32_t>(get_be(p + 24, 4));
  return h;
}

void encode_lcm_log_header(const LcmLogHeader& h, std::uint8_t* p) {
  put_be(h.sync, p, 4);
  put_be(static_cast<std::uint64_t>(h.event_number), p + 4, 8);
  put_be(static_cast<std::uint64_t>(h.timestamp), p + 12, 8);
  put_be(static_cast<std::uint32_t>(h.channel_length), p + 20, 4);
  put_be(static_cast<std::uint32_t>(h.data_length), p + 24, 4);
}

LcmLogWriter::LcmLogWriter(const std::string& path) : path_(path), f_(std::fopen(path.c_str(), "wb")) {
  if (f_ == nullptr) throw std::runtime_error(path + ": cannot create the LCM log: " + std::strerror(errno));
  // A large stdio buffer: one write system call per ~1 MB (~4,000 steps), never one per message.
  std::setvbuf(f_, nullptr, _IOFBF, 1 << 20);
}

LcmLogWriter::~LcmLogWriter() {
  if (f_ != nullptr) std::fclose(f_);
}

void LcmLogWriter::write(std::string_view channel, const std::uint8_t* data, std::size_t size, std::int64_t utime) {
  if (f_ == nullptr) throw std::runtime_error(path_ + ": the LCM log is closed");
  std::uint8_t h[kLcmLogHeaderSize];
  LcmLogHeader e;
  e.event_number = events_;
  e.timestamp = utime;
  e.channel_length = static_cast<std::int32_t>(channel.size());
  e.data_length = static_cast<std::int32_t>(size);
  encode_lcm_log_header(e, h);
  const bool ok = std::fwrite(h, 1, sizeof h, f_) == sizeof h &&
                  std::fwrite(channel.data(), 1, channel.size(), f_) == channel.size() &&
                  (size == 0 || std::fwrite(data, 1, size, f_) == size);
  if (!ok && !failed_) {
    failed_ = true;
    throw std::runtime_error(path_ + ": writing the LCM log failed: " + std::strerror(errno));
  }
  ++events_;
}

void LcmLogWriter::close() {
  if (f_ == nullptr) return;
  const bool ok = std::fflush(f_) == 0 && std::ferror(f_) == 0;
  const int err = errno;
  const bool closed = std::fclose(f_) == 0;
  f_ = nullptr;
  if (!ok || !closed || failed_)
    throw std::runtime_error(path_ + ": writing the LCM log failed: " + std::strerror(err));
}

}  // namespace feeddrive::record
