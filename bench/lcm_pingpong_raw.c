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
 * ping again after 2 ms without an answer.
 *   lcm-pingpong-raw client URL PREFIX COUNT PERIOD_US [GUARD_US [WORK_US]]   -> paced: the
 * real-time floor of liblcm with the plant's rule. It sends ping k at t0 + k*PERIOD_US
 * (clock_nanosleep on an absolute CLOCK_MONOTONIC time, as the plant's period timer does), counts
 * a deadline miss when pong k has not arrived by t0 + (k+1)*PERIOD_US - GUARD_US (the plant's
 * guard, service/src/plant_node.cpp: min(T/5, 25 us)), then busy-works WORK_US (the plant's
 * integration of the period, about 16 us for the paper's plant) before it sleeps to the next
 * period. A missed pong is not waited for (it is late, as a late command is). Prints "paced_misses M of COUNT" and the
 * round-trip p50/p99 in us. The bench runs it on the chain's CPUs at the chain's priority.
 *   lcm-pingpong-raw listen URL PREFIX   -> a passive participant: subscribes to every channel
 * and only reads, as the run's monitor and trajectory do with the plant's states and the
 * controller's commands; ends on the stop ping. The bench adds two to show what a participant
 * that only listens costs the round trip (the kernel copies each datagram to every socket). */
#define _GNU_SOURCE /* ppoll */
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

static void on_any(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
  (void)user;
  int64_t k;
  if (rbuf->data_size < sizeof k || strstr(channel, "_PING") == NULL) return;
  memcpy(&k, rbuf->data, sizeof k);
  if (k == -2) stop = 1;
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
  const struct timespec ts = {(time_t)(timeout_us / 1000000), (long)(timeout_us % 1000000) * 1000};
  if (ppoll(&p, 1, &ts, NULL) <= 0) return 0;
  return lcm_handle(lc) == 0;
}

static int cmp_i64(const void* a, const void* b) {
  const int64_t x = *(const int64_t*)a, y = *(const int64_t*)b;
  return (x > y) - (x < y);
}

/* Paced client: ping k at t0 + k*period; a miss when pong k is not in by t0 + (k+1)*period. */
static int run_paced(const char* ping_channel, long count, long period_us, long guard_us, long work_us) {
  uint8_t ping[kPingBytes] = {0};
  int64_t* rtt = calloc((size_t)count, sizeof *rtt);
  if (!rtt) return 1;
  long misses = 0, n_rtt = 0;
  struct timespec next;
  clock_gettime(CLOCK_MONOTONIC, &next);
  for (int64_t k = 0; k < count; ++k) {
    next.tv_nsec += period_us * 1000;
    while (next.tv_nsec >= 1000000000) {
      next.tv_nsec -= 1000000000;
      ++next.tv_sec;
    }
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, NULL);
    const int64_t start = mono_us();
    memcpy(ping, &k, sizeof k);
    lcm_publish(lc, ping_channel, ping, sizeof ping);
    const int64_t budget = period_us - guard_us;
    while (answered < k && mono_us() - start < budget) handle_within(budget - (mono_us() - start));
    const int64_t took = mono_us() - start;
    if (answered >= k) rtt[n_rtt++] = took;
    if (answered < k || took > budget) ++misses;
    for (const int64_t w = mono_us(); mono_us() - w < work_us;) {}
  }
  qsort(rtt, (size_t)n_rtt, sizeof *rtt, cmp_i64);
  printf("paced_misses %ld of %ld; rtt_p50_us %lld; rtt_p99_us %lld\n", misses, count,
         n_rtt ? (long long)rtt[n_rtt / 2] : -1LL, n_rtt ? (long long)rtt[(n_rtt * 99) / 100] : -1LL);
  free(rtt);
  return 0;
}

int main(int argc, char** argv) {
  if (argc < 4 || (strcmp(argv[1], "client") == 0 && argc < 5)) {
    fprintf(stderr, "usage: lcm-pingpong-raw server|listen|client URL PREFIX [COUNT [PERIOD_US]]\n");
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
  if (strcmp(argv[1], "listen") == 0) {
    lcm_subscribe(lc, ".*", on_any, NULL);
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
  if (argc > 5) {
    const long period_us = strtol(argv[5], NULL, 10);
    const long guard_us = argc > 6 ? strtol(argv[6], NULL, 10) : 0;
    const long work_us = argc > 7 ? strtol(argv[7], NULL, 10) : 0;
    if (count <= 0 || period_us <= 0 || guard_us < 0 || work_us < 0 || guard_us + work_us >= period_us) {
      fprintf(stderr, "error: need COUNT > 0, PERIOD_US > GUARD_US + WORK_US >= 0; got %s %s %ld %ld\n", argv[4],
              argv[5], guard_us, work_us);
      return 2;
    }
    const int rc = run_paced(ping_channel, count, period_us, guard_us, work_us);
    k = -2;
    memcpy(ping, &k, sizeof k);
    for (int i = 0; i < 3; ++i) lcm_publish(lc, ping_channel, ping, sizeof ping);
    lcm_destroy(lc);
    return rc;
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
