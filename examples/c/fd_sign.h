/* Signing and verifying feeddrive messages for a run with --key (docs/security.md), in C with
 * OpenSSL's libcrypto (Debian libssl-dev; link -lcrypto). Header-only; also valid C++.
 *
 * Every top-level feeddrive message ends with `int16_t mac_size; byte mac[mac_size]`. A signed
 * message has mac_size = 32 and
 *     mac = HMAC-SHA256(key, channel || 0x00 || E)
 * where E is the message's LCM encoding up to (not including) mac_size. Encode your message
 * with mac_size = 0 (its last two bytes are then 00 00) into a buffer with 32 bytes to spare,
 * then call fd_sign(); publish the bytes it returns with lcm_publish(). The key is the raw
 * content of the run's key file (16..4096 bytes, mode 0600).
 *
 * tests/integrity/integrity_test.cpp checks both functions against the C++ processes' own
 * signer (service/integrity.hpp). */
#ifndef FEEDDRIVE_EXAMPLES_FD_SIGN_H
#define FEEDDRIVE_EXAMPLES_FD_SIGN_H

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <stddef.h>
#include <string.h>

/* The mac of `channel` and the `body_size` bytes of `body` into out[32]. 0 on failure. */
static inline int fd_mac(const unsigned char* key, int key_len, const char* channel, const unsigned char* body,
                         size_t body_size, unsigned char* out) {
  unsigned char in[4096];
  const size_t clen = strlen(channel);
  if (clen + 1 + body_size > sizeof in) return 0; /* feeddrive messages are < 1 KB */
  memcpy(in, channel, clen + 1);                  /* the channel and its NUL */
  memcpy(in + clen + 1, body, body_size);
  return HMAC(EVP_sha256(), key, key_len, in, clen + 1 + body_size, out, NULL) != NULL;
}

/* buf[0, n): a message encoded with mac_size = 0, and 32 more bytes of room. Writes mac_size = 32
 * and the mac; returns the signed size (n + 32), or 0 on failure. */
static inline size_t fd_sign(const unsigned char* key, int key_len, const char* channel, unsigned char* buf, size_t n) {
  if (n < 10 || buf[n - 2] != 0 || buf[n - 1] != 0) return 0; /* not an unsigned encoding */
  const size_t body = n - 2;
  buf[body] = 0;
  buf[body + 1] = 32;
  return fd_mac(key, key_len, channel, buf, body, buf + body + 2) ? body + 34 : 0;
}

/* 1 if data[0, n) ends with mac_size = 32 and the right mac for `channel`, else 0. */
static inline int fd_verify(const unsigned char* key, int key_len, const char* channel, const unsigned char* data,
                            size_t n) {
  unsigned char expect[32];
  if (n < 42 || data[n - 34] != 0 || data[n - 33] != 32) return 0;
  if (!fd_mac(key, key_len, channel, data, n - 34, expect)) return 0;
  return CRYPTO_memcmp(expect, data + n - 32, 32) == 0; /* constant time */
}

#endif
