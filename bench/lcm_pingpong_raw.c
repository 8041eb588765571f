/* lcm-pingpong-raw: the ceiling of a lockstep step, with liblcm only. A minimal C program that
 * uses nothing but lcm_create, lcm_subscribe, lcm_publish and lcm_handle (LCM 1.3.1's C API), so
 * it measures liblcm and the kernel, not the project's code. Same shape as bench/lcm_pingpong.cpp:
 * the client publishes a ping on <prefix>_PING, the server answers each with a pong on
 * <prefix>_PONG, the client sends the next ping when the pong arrives: one round trip per step,
 * like the plant <-> controller exchange. Payloads have the encoded sizes of a drive_state_t
 * (ping) and a control_command_t (pong); the first 8 bytes carry the step number.
 *   lcm-pingpong-raw server URL PREFIX
 *   lcm-pingpong-raw client URL PREFIX COUNT     -> prints "pingpong_rate <round trips per s>"
 * A ping with step -2 ends the server. Loss is recovered as in lcm-pingpong: the client sends the
 * ping again after 2 ms without an answer. */
#include <lcm/lcm.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { kPingBytes = 167, kPongBytes = 66 }; /* drive_state_t / control_command_t encoded sizes (unsigned) */

static int64_t mono_us(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

static lcm_t* lc;
static char pong_channel[128];
static int64_t answered = -3; /* client: highest step answered */
static int stop;

static void on_ping(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
  (void)channel;
  (void)user;
  uint8_t pong[kPongBytes] = {0};
  int64_t k;
  if (rbuf->data_size < sizeof k) return;
  memcpy(&k, rbuf->data, sizeof k);
  if (k == -2) {
    stop = 1;
    return;
  }
  memcpy(pong, &k, sizeof k);
  lcm_publish(lc, pong_channel, pong, sizeof pong);
}

static void on_pong(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
  (void)channel;
  (void)user;
  int64_t k;
  if (rbuf->data_size < sizeof k) return;
  memcpy(&k, rbuf->data, sizeof k);
  if (k > answered) answered = k;
}

/* Waits up to timeout_us for a message and handles one; 1 if one was handled. */
static int handle_within(int64_t timeout_us) {
  struct pollfd p = {lcm_get_fileno(lc), POLLIN, 0};
  if (poll(&p, 1, (int)((timeout_us + 999) / 1000)) <= 0) return 0;
  return lcm_handle(lc) == 0;
}

int main(int argc, char** argv) {
  if (argc < 4 || (strcmp(argv[1], "client") == 0 && argc < 5)) {
    fprintf(stderr, "usage: lcm-pingpong-raw server|client URL PREFIX [COUNT]\n");
    return 2;
  }
  lc = lcm_create(argv[2]);
  if (!lc) {
    fprintf(stderr, "error: cannot open LCM at %s\n", argv[2]);
    return 1;
  }
  char ping_channel[128];
  snprintf(ping_channel, sizeof ping_channel, "%s_PING", argv[3]);
  snprintf(pong_channel, sizeof pong_channel, "%s_PONG", argv[3]);
  if (strcmp(argv[1], "server") == 0) {
    lcm_subscribe(lc, ping_channel, on_ping, NULL);
    int64_t last = mono_us();
    while (!stop && mono_us() - last < 30000000)
      if (handle_within(100000)) last = mono_us();
    lcm_destroy(lc);
    return 0;
  }
  const long count = strtol(argv[4], NULL, 10);
  lcm_subscribe(lc, pong_channel, on_pong, NULL);
  uint8_t ping[kPingBytes] = {0};
  int64_t k = -1; /* warm-up until the server answers (it may start later) */
  const int64_t start_wait = mono_us();
  while (answered < -1) {
    if (mono_us() - start_wait > 30000000) {
      fprintf(stderr, "error: no pong from the server within 30 s\n");
      return 1;
    }
    memcpy(ping, &k, sizeof k);
    lcm_publish(lc, ping_channel, ping, sizeof ping);
    handle_within(10000);
  }
  const int64_t t0 = mono_us();
  for (k = 0; k < count; ++k) {
    memcpy(ping, &k, sizeof k);
    lcm_publish(lc, ping_channel, ping, sizeof ping);
    int64_t sent = mono_us();
    while (answered < k) {
      handle_within(2000);
      if (answered < k && mono_us() - sent > 2000) { /* lost: send again */
        lcm_publish(lc, ping_channel, ping, sizeof ping);
        sent = mono_us();
      }
    }
  }
  const double dt = (double)(mono_us() - t0) * 1e-6;
  k = -2;
  memcpy(ping, &k, sizeof k);
  for (int i = 0; i < 3; ++i) lcm_publish(lc, ping_channel, ping, sizeof ping);
  printf("pingpong_rate %.1f\n", (double)count / dt);
  lcm_destroy(lc);
  return 0;
}
