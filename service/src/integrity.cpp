#include "feeddrive/service/integrity.hpp"
#include "feeddrive/common/text_file.hpp"

#include <fcntl.h>
#include <openssl/core_names.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/params.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <stdexcept>

namespace feeddrive::service {
namespace {

// Collects the names of differing fields; doubles bit for bit.
struct Diff {
  std::string names;
  void add(const char* name) { names += (names.empty() ? "" : ", ") + std::string(name); }
  void f(const char* name, double a, double b) {
    if (std::memcmp(&a, &b, sizeof a) != 0) add(name);
  }
  template <typename I>
  void i(const char* name, I a, I b) {
    if (a != b) add(name);
  }
};

}  // namespace

std::string differing_fields(const control_command_t& a, const control_command_t& b) {
  Diff d;
  d.i("seq", a.seq, b.seq);
  d.f("t", a.t, b.t);
  d.f("u", a.u, b.u);
  d.f("u_unsaturated", a.u_unsaturated, b.u_unsaturated);
  d.f("sliding", a.sliding, b.sliding);
  d.f("z_estimate", a.z_estimate, b.z_estimate);
  return d.names;
}

std::string differing_fields(const drive_state_t& a, const drive_state_t& b) {
  Diff d;
  d.i("seq", a.seq, b.seq);
  d.f("t", a.t, b.t);
  d.i("steps", a.steps, b.steps);
  d.i("end_of_run", a.end_of_run, b.end_of_run);
  d.i("realtime", a.realtime, b.realtime);
  d.f("x_measured", a.x_measured, b.x_measured);
  d.f("v_measured", a.v_measured, b.v_measured);
  d.i("truth.valid", a.truth.valid, b.truth.valid);
  d.f("truth.x", a.truth.x, b.truth.x);
  d.f("truth.v", a.truth.v, b.truth.v);
  d.f("truth.z", a.truth.z, b.truth.z);
  d.f("truth.fg", a.truth.fg, b.truth.fg);
  d.f("truth.i", a.truth.i, b.truth.i);
  d.i("previous.seq", a.previous.seq, b.previous.seq);
  d.f("previous.u", a.previous.u, b.previous.u);
  d.i("previous.forces_valid", a.previous.forces_valid, b.previous.forces_valid);
  d.f("previous.f_thrust", a.previous.f_thrust, b.previous.f_thrust);
  d.f("previous.f_friction", a.previous.f_friction, b.previous.f_friction);
  d.f("previous.f_ripple", a.previous.f_ripple, b.previous.f_ripple);
  d.f("previous.f_grinding", a.previous.f_grinding, b.previous.f_grinding);
  d.i("rejected_commands", a.rejected_commands, b.rejected_commands);
  d.i("missed_deadlines", a.missed_deadlines, b.missed_deadlines);
  d.i("overruns", a.overruns, b.overruns);
  d.f("start_late_us", a.start_late_us, b.start_late_us);
  d.i("safe_state", a.safe_state, b.safe_state);
  return d.names;
}

std::string differing_fields(const reference_t& a, const reference_t& b) {
  Diff d;
  d.i("seq", a.seq, b.seq);
  d.f("t", a.t, b.t);
  d.f("position", a.position, b.position);
  d.f("velocity", a.velocity, b.velocity);
  d.f("acceleration", a.acceleration, b.acceleration);
  d.f("jerk", a.jerk, b.jerk);
  return d.names;
}

std::int64_t draw_run_id() {
  std::random_device rd;
  std::uint64_t v = 0;
  // 53 bits: bindings that hold integers in doubles (Lua 5.2, JavaScript) carry it exactly.
  while (v == 0) v = ((static_cast<std::uint64_t>(rd()) << 32) ^ rd()) & ((std::uint64_t{1} << 53) - 1);
  return static_cast<std::int64_t>(v);
}

namespace {
std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}
}  // namespace

std::int64_t keyed_run_id(std::int64_t run_id, std::int64_t nonce) {
  if (nonce == 0) return run_id;
  const std::uint64_t m = (std::uint64_t{1} << 53) - 1;
  const std::uint64_t h =
      splitmix64(static_cast<std::uint64_t>(run_id) ^ splitmix64(static_cast<std::uint64_t>(nonce)));
  return static_cast<std::int64_t>(1 + h % m);
}

std::array<std::uint8_t, 32> hmac_sha256(const std::string& key, const std::uint8_t* data, std::size_t size) {
  std::array<std::uint8_t, 32> out{};
  unsigned int n = 0;
  if (HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()), data, size, out.data(), &n) == nullptr || n != 32)
    throw std::runtime_error("HMAC-SHA256 failed (libcrypto)");
  return out;
}

std::string sha256_hex(const std::string& bytes) {
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), md, &n, EVP_sha256(), nullptr) != 1 || n != 32)
    throw std::runtime_error("SHA-256 failed (libcrypto)");
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < n; ++i) {
    out += hex[md[i] >> 4];
    out += hex[md[i] & 15];
  }
  return out;
}

std::string read_key_file(const std::string& path) {
  // A symlink is followed (a Kubernetes or Docker secret is one): every check below is on the
  // file it leads to, as opened (fstat), so swapping the link after the check changes nothing.
  std::string where = "--key " + path + ": ";
  struct stat lst {};
  if (::lstat(path.c_str(), &lst) == 0 && S_ISLNK(lst.st_mode)) {
    std::error_code ec;
    const auto target = std::filesystem::canonical(path, ec);
    where = "--key " + path + " (a link to " + (ec ? std::string("a missing file") : target.string()) + "): ";
  }
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);  // a FIFO must not block
  if (fd < 0) throw std::invalid_argument(where + "cannot open it (" + std::strerror(errno) + ")");
  struct stat st {};
  std::string key;
  try {
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
      throw std::invalid_argument(where + "not a regular file (" + text::non_regular_kind(st.st_mode) + ")");
    if (st.st_uid != ::geteuid())
      throw std::invalid_argument(where + "owned by another user (uid " + std::to_string(st.st_uid) +
                                  "); a key must be its user's own");
    if ((st.st_mode & 077) != 0) {
      char mode[8];
      std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
      throw std::invalid_argument(where + "mode " + mode + " lets group or others access it; run chmod 600 " + path);
    }
    if (st.st_size < 16 || st.st_size > 4096)
      throw std::invalid_argument(where + std::to_string(st.st_size) +
                                  " bytes; a key has 16..4096 (e.g. head -c 32 /dev/urandom > " + path + ")");
    key.resize(static_cast<std::size_t>(st.st_size));
    std::size_t got = 0;
    while (got < key.size()) {
      const ssize_t r = ::read(fd, key.data() + got, key.size() - got);
      if (r <= 0) throw std::invalid_argument(where + "read failed");
      got += static_cast<std::size_t>(r);
    }
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
  return key;
}

MessageAuth::MessageAuth(const std::string& key) {
  mac_alg_ = EVP_MAC_fetch(nullptr, "HMAC", nullptr);
  ctx_ = mac_alg_ ? EVP_MAC_CTX_new(mac_alg_) : nullptr;
  char digest[] = "SHA256";
  const OSSL_PARAM params[] = {OSSL_PARAM_construct_utf8_string(OSSL_MAC_PARAM_DIGEST, digest, 0),
                               OSSL_PARAM_construct_end()};
  if (ctx_ == nullptr ||
      EVP_MAC_init(ctx_, reinterpret_cast<const unsigned char*>(key.data()), key.size(), params) != 1) {
    EVP_MAC_CTX_free(ctx_);
    EVP_MAC_free(mac_alg_);
    throw std::runtime_error("cannot set up HMAC-SHA256 (libcrypto)");
  }
}

MessageAuth::~MessageAuth() {
  EVP_MAC_CTX_free(ctx_);
  EVP_MAC_free(mac_alg_);
}

void MessageAuth::mac(const std::string& channel, const std::uint8_t* body, std::size_t size, std::uint8_t* out) const {
  // A null key re-initialises the context with the key it holds (OpenSSL 3: EVP_MAC_init(3)).
  const unsigned char nul = 0;
  std::size_t n = 0;
  if (EVP_MAC_init(ctx_, nullptr, 0, nullptr) != 1 ||
      EVP_MAC_update(ctx_, reinterpret_cast<const unsigned char*>(channel.data()), channel.size()) != 1 ||
      EVP_MAC_update(ctx_, &nul, 1) != 1 || EVP_MAC_update(ctx_, body, size) != 1 ||
      EVP_MAC_final(ctx_, out, &n, kMacSize) != 1 || n != kMacSize)
    throw std::runtime_error("HMAC-SHA256 failed (libcrypto)");
}

void MessageAuth::sign(const std::string& channel, std::uint8_t* data, std::size_t size) const {
  if (size < kTrailer) throw std::logic_error("MessageAuth::sign: message shorter than its trailer");
  data[size - kTrailer] = 0;
  data[size - kTrailer + 1] = static_cast<std::uint8_t>(kMacSize);
  mac(channel, data, size - kTrailer, data + size - kMacSize);
}

bool MessageAuth::verify(const std::string& channel, const std::uint8_t* data, std::size_t size) const {
  if (size < 8 + kTrailer || data[size - kTrailer] != 0 || data[size - kTrailer + 1] != kMacSize) return false;
  std::uint8_t expect[kMacSize];
  mac(channel, data, size - kTrailer, expect);
  return CRYPTO_memcmp(expect, data + size - kMacSize, kMacSize) == 0;
}

}  // namespace feeddrive::service
