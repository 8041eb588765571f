/* drive_adapter.c: a feeddrive plant in C, as a drive adapter for real hardware would be written
 * (docs/external-plant.md). It takes the plant's role of a run started with
 *     feeddrive-launch SCENARIO --out DIR --external plant [--realtime] [--key FILE]
 * and follows docs/external-plant.md step by step: heartbeats with its run id first, run_info_t,
 * flow control against the monitor's acked_seq, re-publishing a pending state, answering resend
 * requests, the end-of-run state, signing with --key, and (real time) the wall-clock handshake.
 *
 * The "hardware" is a drive model of its own, not feeddrive's (so a run checks the framework
 * against a plant it did not make):
 *     m x'' = Ka*Kf*u - b*v - g(v)*tanh(v / v_c),  g(v) = Fc + (Fs - Fc)*exp(-|v/vs|^delta)
 * (viscous friction and a smooth Stribeck curve, no bristles) integrated with classical RK4, 10
 * substeps a period, u held over the period; the encoder quantises the position to q
 * (x_m = q*round(x/q)) and the velocity is the encoder difference (x_m[k] - x_m[k-1]) / T, as a
 * drive computes it. m, Ka*Kf, b, Fc, Fs, vs, delta, the input limit, x(0), v(0) and q (0.1 um
 * when the run's sensor is ideal: this "hardware" has an encoder) come from run_info_t.plant by
 * their scenario keys (read_drive); T, the step count, the limits and the protocol's timeouts
 * from run_info_t's own fields: nothing about the run is configured here by hand.
 *
 * Usage: drive_adapter [--url URL] [--prefix P] [--key FILE] [--run-id N]
 *        test hooks (tests/service/hil_test.sh): [--skip-at K] publishes state K+1 in place of K;
 *        [--exit-at K] exits without a word at step K (a drive that lost power).
 * Build (tests/service/hil_test.sh does): lcm-gen -c the files of lcmtypes/, then
 *     cc -Iexamples/c -IGEN drive_adapter.c GEN/feeddrive_*.c -llcm -lcrypto -lm */
#define _GNU_SOURCE /* ppoll */
#include <lcm/lcm.h>
#include <math.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "fd_sign.h"
#include "feeddrive_control_command_t.h"
#include "feeddrive_drive_state_t.h"
#include "feeddrive_process_status_t.h"
#include "feeddrive_resend_request_t.h"
#include "feeddrive_run_info_t.h"

#define CONTRACT_VERSION 4 /* docs/lcm-contract.md, Versions */
#define KEEP 4096          /* states kept for resend requests */
#define V_COULOMB 1e-4     /* m/s: the smoothing velocity of this drive's Coulomb friction */

static lcm_t* lc;
static char ch_state[80], ch_cmd[80], ch_status[80], ch_resend[80], ch_info[80];
static unsigned char key[4096];
static int key_len; /* 0: unsigned run */
static int64_t run_id;
static int64_t run_nonce; /* with a key: this run's nonce (docs/security.md, "Replays across runs") */
static feeddrive_run_info_t info;
static int have_info;
static int64_t acked = -1, seq = -1, resends, rejected, missed, invalid, unauthenticated;
static int monitor_done, monitor_seen;
static char failure[700];
static feeddrive_control_command_t cmd; /* the newest command */
static double cmd_arrival;              /* real time: when it came [s, monotonic] */
static int have_cmd;
static feeddrive_drive_state_t kept[KEEP];
static double x, v, x_m_prev, q; /* the drive: position, velocity, last encoder reading, resolution */
/* The drive's parameters, from run_info_t.plant (read_drive). */
static struct {
  double mass, thrust_gain, viscous, coulomb, stiction, stribeck_velocity, delta, input_limit, x0, v0, quantization;
} drive;

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Encodes, signs (with a key) and publishes: every message this adapter sends goes through here. */
#define PUBLISH(type, channel, msg)                                                          \
  do {                                                                                       \
    unsigned char buf_[2048];                                                                \
    (msg)->run_id = run_id;                                                                  \
    (msg)->mac_size = 0;                                                                     \
    (msg)->mac = NULL;                                                                       \
    int n_ = type##_encode(buf_, 0, (int)sizeof buf_ - 32, (msg));                           \
    if (n_ > 0 && key_len > 0) n_ = (int)fd_sign(key, key_len, (channel), buf_, (size_t)n_); \
    if (n_ > 0) lcm_publish(lc, (channel), buf_, (unsigned)n_);                              \
  } while (0)

/* A received message: verified (with a key) before it is decoded; 0 when it is to be dropped. */
static int admit(const lcm_recv_buf_t* rb, const char* channel) {
  if (key_len > 0 && !fd_verify(key, key_len, channel, rb->data, rb->data_size)) {
    ++unauthenticated;
    return 0;
  }
  return 1;
}

/* A random number in 1 .. 2^53 - 1 (exact in a double). */
static int64_t draw53(void) {
  FILE* r = fopen("/dev/urandom", "rb");
  uint64_t b = 0;
  while (b == 0 && r && fread(&b, sizeof b, 1, r) == 1) b &= (UINT64_C(1) << 53) - 1;
  if (r) fclose(r);
  return (int64_t)b;
}

/* keyed_run_id(R, N) = 1 + (splitmix64(R xor splitmix64(N)) mod (2^53 - 1)) (docs/security.md). */
static uint64_t splitmix64(uint64_t x) {
  x += UINT64_C(0x9E3779B97F4A7C15);
  x = (x ^ (x >> 30)) * UINT64_C(0xBF58476D1CE4E5B9);
  x = (x ^ (x >> 27)) * UINT64_C(0x94D049BB133111EB);
  return x ^ (x >> 31);
}
static int64_t keyed_run_id(int64_t r, int64_t n) {
  return (int64_t)(1 + splitmix64((uint64_t)r ^ splitmix64((uint64_t)n)) % ((UINT64_C(1) << 53) - 1));
}

static void heartbeat(const char* state, const char* message) {
  struct timespec w;
  clock_gettime(CLOCK_REALTIME, &w);
  feeddrive_process_status_t m;
  memset(&m, 0, sizeof m);
  m.utime = (int64_t)w.tv_sec * 1000000 + w.tv_nsec / 1000;
  m.run_nonce = run_nonce;
  m.role = "plant";
  m.state = (char*)state;
  m.message = (char*)message;
  m.seq = seq;
  m.acked_seq = -1;
  m.resends = resends;
  m.invalid = invalid;
  m.unauthenticated = unauthenticated;
  m.contract_version = CONTRACT_VERSION;
  PUBLISH(feeddrive_process_status_t, ch_status, &m);
}

static void on_info(const lcm_recv_buf_t* rb, const char* ch, void* u) {
  (void)u;
  if (have_info || !admit(rb, ch)) return;
  feeddrive_run_info_t m;
  if (feeddrive_run_info_t_decode(rb->data, 0, rb->data_size, &m) < 0) {
    ++invalid;
    return;
  }
  if (m.run_id != run_id) {
    feeddrive_run_info_t_decode_cleanup(&m);
    return;
  }         /* another run's */
  info = m; /* kept for the whole run: no decode_cleanup */
  have_info = 1;
}

static void on_status(const lcm_recv_buf_t* rb, const char* ch, void* u) {
  (void)u;
  if (!admit(rb, ch)) return;
  feeddrive_process_status_t m;
  if (feeddrive_process_status_t_decode(rb->data, 0, rb->data_size, &m) < 0) {
    ++invalid;
    return;
  }
  if (m.run_id == run_id && strcmp(m.role, "plant") != 0) {
    const int run_role = !strcmp(m.role, "controller") || !strcmp(m.role, "trajectory") || !strcmp(m.role, "monitor");
    if (run_role && !strcmp(m.state, "failed") && !failure[0])
      snprintf(failure, sizeof failure, "%s failed at step %lld: %s", m.role, (long long)m.seq, m.message);
    if (!strcmp(m.role, "monitor")) {
      monitor_seen = 1;
      if (m.acked_seq > acked) acked = m.acked_seq; /* flow control */
      if (!strcmp(m.state, "done") || !strcmp(m.state, "failed")) monitor_done = 1;
    }
  }
  feeddrive_process_status_t_decode_cleanup(&m);
}

static void on_command(const lcm_recv_buf_t* rb, const char* ch, void* u) {
  (void)u;
  if (!admit(rb, ch)) return;
  feeddrive_control_command_t m;
  if (feeddrive_control_command_t_decode(rb->data, 0, rb->data_size, &m) < 0) {
    ++invalid;
    return;
  }
  if (m.run_id == run_id && (!have_cmd || m.seq > cmd.seq)) { /* repeats and older ones: ignored */
    cmd = m;
    cmd.mac = NULL;
    cmd_arrival = now();
    have_cmd = 1;
  }
  feeddrive_control_command_t_decode_cleanup(&m);
}

static void on_resend(const lcm_recv_buf_t* rb, const char* ch, void* u) {
  (void)u;
  if (!admit(rb, ch)) return;
  feeddrive_resend_request_t r;
  if (feeddrive_resend_request_t_decode(rb->data, 0, rb->data_size, &r) < 0) {
    ++invalid;
    return;
  }
  if (r.run_id == run_id && !strcmp(r.channel, ch_state) && r.seq >= 0 && kept[r.seq % KEEP].seq == r.seq &&
      kept[r.seq % KEEP].steps > 0) {
    PUBLISH(feeddrive_drive_state_t, ch_state, &kept[r.seq % KEEP]);
    ++resends;
  }
  feeddrive_resend_request_t_decode_cleanup(&r);
}

/* Handles what arrives within `timeout` seconds (at least one wait; ns resolution: ppoll). */
static void handle(double timeout) {
  struct pollfd p = {lcm_get_fileno(lc), POLLIN, 0};
  if (timeout < 0) timeout = 0;
  struct timespec ts = {(time_t)timeout, (long)((timeout - (double)(time_t)timeout) * 1e9)};
  const struct timespec zero = {0, 0};
  if (ppoll(&p, 1, &ts, NULL) > 0) lcm_handle(lc);
  while (ppoll(&p, 1, &zero, NULL) > 0) lcm_handle(lc);
}

/* The number of the drive's parameter `key` (run_info_t.plant, contract 4: every key of the
 * plant's list by its scenario key, docs/lcm-contract.md): 1, or 0 when the run has none. */
static int parameter(const char* key, double* out) {
  for (int i = 0; i < info.plant_count; ++i) {
    if (strcmp(info.plant[i].key, key) != 0 || info.plant[i].name[0] != '\0') continue;
    *out = info.plant[i].value;
    return 1;
  }
  return 0;
}

/* The drive's parameters from run_info_t.plant; 0 with `why` naming a missing key. */
static int read_drive(char* why, size_t size) {
  const struct {
    const char* key;
    double* to;
  } keys[] = {{"mass", &drive.mass},
              {"thrust_gain", &drive.thrust_gain},
              {"friction.viscous", &drive.viscous},
              {"friction.coulomb_force", &drive.coulomb},
              {"friction.static_force", &drive.stiction},
              {"friction.stribeck_velocity", &drive.stribeck_velocity},
              {"friction.stribeck_exponent", &drive.delta},
              {"input_limit", &drive.input_limit},
              {"initial.position", &drive.x0},
              {"initial.velocity", &drive.v0},
              {"sensor.quantization", &drive.quantization}};
  for (size_t i = 0; i < sizeof keys / sizeof keys[0]; ++i) {
    if (!parameter(keys[i].key, keys[i].to)) {
      snprintf(why, size, "run_info_t.plant has no number %s (docs/lcm-contract.md)", keys[i].key);
      return 0;
    }
  }
  return 1;
}

/* The drive: x'' = (Ka*Kf*u - b*v - g(v)*tanh(v/v_c)) / m over one period, RK4 with 10 substeps;
 * g(v) = Fc + (Fs - Fc)*exp(-|v/vs|^delta), the Stribeck curve (Xie & Liang eq. 7). */
static double accel(double vel, double u) {
  const double g =
      drive.coulomb + (drive.stiction - drive.coulomb) * exp(-pow(fabs(vel / drive.stribeck_velocity), drive.delta));
  return (drive.thrust_gain * u - drive.viscous * vel - g * tanh(vel / V_COULOMB)) / drive.mass;
}
static void integrate(double u, double T) {
  const double h = T / 10.0;
  for (int i = 0; i < 10; ++i) {
    const double k1x = v, k1v = accel(v, u);
    const double k2x = v + 0.5 * h * k1v, k2v = accel(v + 0.5 * h * k1v, u);
    const double k3x = v + 0.5 * h * k2v, k3v = accel(v + 0.5 * h * k2v, u);
    const double k4x = v + h * k3v, k4v = accel(v + h * k3v, u);
    x += h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
    v += h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
  }
}

/* Builds and publishes state k; u_prev is what was applied during step k-1. */
static void publish_state(int64_t k, double u_prev, int safe) {
  feeddrive_drive_state_t* m = &kept[k % KEEP];
  memset(m, 0, sizeof *m);
  const double T = info.control_period;
  const double xm = q > 0 ? q * round(x / q) : x;
  m->seq = k;
  m->t = (double)k * T;
  m->steps = info.steps;
  m->end_of_run = k >= info.steps;
  m->realtime = !strcmp(info.mode, "realtime");
  m->x_measured = xm;
  m->v_measured = k == 0 ? drive.v0 : (xm - x_m_prev) / T;
  if (!m->end_of_run) x_m_prev = xm;
  m->truth.valid = 0; /* hardware: no true state */
  m->previous.seq = k - 1;
  m->previous.u = k == 0 ? NAN : u_prev;
  m->previous.forces_valid = 0; /* a drive does not measure its force breakdown */
  m->previous.f_thrust = m->previous.f_friction = m->previous.f_ripple = m->previous.f_grinding = NAN;
  m->rejected_commands = (int32_t)rejected;
  m->missed_deadlines = (int32_t)missed;
  m->safe_state = (int8_t)safe;
  PUBLISH(feeddrive_drive_state_t, ch_state, m);
  seq = k;
}

/* The command for a step, as the plant admits it: NaN/inf -> 0 V (or the last good one), |u| clipped. */
static double admit_u(double u, double fallback) {
  if (!isfinite(u)) {
    ++rejected;
    return fallback;
  }
  if (fabs(u) > drive.input_limit) {
    ++rejected;
    return u > 0 ? drive.input_limit : -drive.input_limit;
  }
  return u;
}

static int fail(const char* message) {
  for (int i = 0; i < 3; ++i) heartbeat("failed", message);
  fprintf(stderr, "drive_adapter: %s\n", message);
  return 1;
}

int main(int argc, char** argv) {
  const char *url = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304", *prefix = "FD", *key_file = NULL;
  long long skip_at = -1, exit_at = -1;
  run_id = 0;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!strcmp(argv[i], "--url")) url = argv[i + 1];
    else if (!strcmp(argv[i], "--prefix")) prefix = argv[i + 1];
    else if (!strcmp(argv[i], "--key")) key_file = argv[i + 1];
    else if (!strcmp(argv[i], "--run-id")) run_id = atoll(argv[i + 1]);
    else if (!strcmp(argv[i], "--skip-at")) skip_at = atoll(argv[i + 1]);
    else if (!strcmp(argv[i], "--exit-at")) exit_at = atoll(argv[i + 1]);
    else {
      fprintf(stderr, "drive_adapter: unknown option %s\n", argv[i]);
      return 2;
    }
  }
  if (key_file) {
    FILE* f = fopen(key_file, "rb");
    if (!f) {
      fprintf(stderr, "drive_adapter: --key %s: cannot open it\n", key_file);
      return 2;
    }
    key_len = (int)fread(key, 1, sizeof key, f);
    fclose(f);
    if (key_len < 16) {
      fprintf(stderr, "drive_adapter: --key %s: fewer than 16 bytes\n", key_file);
      return 2;
    }
  }
  /* Step 1: a run id of its own (the launcher's --run-id if given), 53 bits, never 0. With a
   * key, a fresh nonce N binds it to this run: the run id on the wire is keyed_run_id(R, N). */
  if (run_id == 0) run_id = draw53();
  if (key_file) {
    run_nonce = draw53();
    run_id = keyed_run_id(run_id, run_nonce);
  }
  snprintf(ch_state, sizeof ch_state, "%s_STATE", prefix);
  snprintf(ch_cmd, sizeof ch_cmd, "%s_CMD", prefix);
  snprintf(ch_status, sizeof ch_status, "%s_STATUS", prefix);
  snprintf(ch_resend, sizeof ch_resend, "%s_RESEND", prefix);
  snprintf(ch_info, sizeof ch_info, "%s_INFO", prefix);
  lc = lcm_create(url);
  if (!lc) {
    fprintf(stderr, "drive_adapter: cannot open LCM at %s\n", url);
    return 1;
  }
  lcm_subscribe(lc, ch_info, on_info, NULL);
  lcm_subscribe(lc, ch_status, on_status, NULL);
  lcm_subscribe(lc, ch_cmd, on_command, NULL);
  lcm_subscribe(lc, ch_resend, on_resend, NULL);
  for (int i = 0; i < KEEP; ++i) kept[i].seq = -1;

  /* Step 2: heartbeats ("starting") until run_info_t of this run comes; ask for it each 100 ms. */
  double last_beat = -1, last_ask = -1;
  for (const double start = now(); !have_info;) {
    handle(0.01);
    const double t = now();
    if (t - last_beat >= 0.1) {
      heartbeat("starting", "");
      last_beat = t;
    }
    if (monitor_seen && t - last_ask >= 0.1) {
      feeddrive_resend_request_t r;
      memset(&r, 0, sizeof r);
      r.requester = "plant";
      r.channel = ch_info;
      r.seq = 0;
      PUBLISH(feeddrive_resend_request_t, ch_resend, &r);
      last_ask = t;
    }
    if (t - start > 30.0)
      return fail("no run_info_t from the monitor within 30 s (is feeddrive-launch running with --external plant?)");
  }
  if (info.contract_version != CONTRACT_VERSION) {
    char m[200];
    snprintf(m, sizeof m, "the run speaks contract version %d, this adapter %d: rebuild it with the run's lcmtypes/",
             info.contract_version, CONTRACT_VERSION);
    return fail(m);
  }
  char why[200];
  if (!read_drive(why, sizeof why)) return fail(why);
  const double T = info.control_period, resend = info.resend_interval, step_timeout = info.step_timeout;
  const int realtime = !strcmp(info.mode, "realtime");
  x = drive.x0;
  v = drive.v0;
  q = drive.quantization > 0 ? drive.quantization : 1e-7;
  fprintf(stderr,
          "drive_adapter: run %lld, %s (%s): T = %g s, %lld steps, m = %g kg, Ka*Kf = %g N/V, b = %g N*s/m, "
          "Fc = %g N, Fs = %g N, vs = %g m/s, delta = %g, q = %g m, x0 = %g m, scenario sha256 %.12s...\n",
          (long long)run_id, info.scenario, info.mode, T, (long long)info.steps, drive.mass, drive.thrust_gain,
          drive.viscous, drive.coulomb, drive.stiction, drive.stribeck_velocity, drive.delta, q, drive.x0,
          info.scenario_hash);

  /* Step 3: the steps. */
  double u_prev = 0.0, last_good = 0.0, t0 = 0.0;
  int bad_in_a_row = 0, safe = 0;
  for (int64_t k = 0; k < info.steps; ++k) {
    if (k == exit_at) _exit(3); /* test hook: the drive lost power */
    /* Flow control: never more than monitor_window steps ahead of the monitor's acked_seq. */
    for (const double w0 = now(); info.monitor_window > 0 && k - acked >= info.monitor_window;) {
      handle(resend);
      if (failure[0]) return fail(failure);
      if (now() - w0 > step_timeout) return fail("no acknowledgement from the monitor within the step timeout");
      if (now() - last_beat >= 0.1) {
        heartbeat("running", "");
        last_beat = now();
      }
    }
    const int64_t published = (k == skip_at) ? k + 1 : k; /* test hook: a skipped step number */
    if (!realtime || k == 0) {
      /* Lockstep (and the real-time start handshake at step 0): state k, re-published every
       * resend interval until command k comes. */
      publish_state(published, u_prev, safe);
      double last_sent = now();
      const double since = now(), limit = k == 0 ? info.start_timeout : step_timeout;
      while (!have_cmd || cmd.seq < k) {
        handle(resend);
        const double t = now();
        if (failure[0]) return fail(failure);
        if (t - last_sent >= resend) {
          PUBLISH(feeddrive_drive_state_t, ch_state, &kept[published % KEEP]);
          ++resends;
          last_sent = t;
        }
        if (t - last_beat >= 0.1) {
          heartbeat("running", "");
          last_beat = t;
        }
        if (t - since > limit) {
          char m[200];
          snprintf(m, sizeof m, "no command from the controller for step %lld within %g s", (long long)k, limit);
          return fail(m);
        }
      }
      if (realtime) t0 = now(); /* the clock starts when command 0 has come */
    } else {
      /* Real time: state k at w_k = t0 + k*T, first thing in the period, whether or not command
       * k-1 came; then command k is awaited until w_{k+1} - guard. */
      const double w = t0 + (double)k * T;
      while (now() < w) handle(w - now());
      publish_state(published, u_prev, safe);
      const double deadline = w + T - fmin(T / 5, 25e-6);
      while ((!have_cmd || cmd.seq < k) && now() < deadline) handle(deadline - now());
      if (failure[0]) return fail(failure);
      if (now() - last_beat >= 0.1) {
        heartbeat("running", "");
        last_beat = now();
      }
    }
    /* The command of step k (real time: the newest that came on time, else the last good one). */
    double u;
    if (have_cmd && cmd.seq == k) {
      u = admit_u(cmd.u, realtime ? last_good : 0.0);
      bad_in_a_row = isfinite(cmd.u) ? 0 : bad_in_a_row + 1;
      if (isfinite(cmd.u)) last_good = u;
    } else {
      ++missed;
      ++bad_in_a_row;
      u = last_good;
    }
    if (bad_in_a_row >= info.max_bad_commands && !safe) {
      safe = 1;
      fprintf(stderr, "drive_adapter: %d missed or invalid commands in a row at step %lld: safe state, zero thrust\n",
              bad_in_a_row, (long long)k);
    }
    if (safe && bad_in_a_row == 0) safe = 0;
    if (safe) u = 0.0;
    integrate(u, T);
    u_prev = u;
  }
  /* Step 4: the end-of-run state, re-published every 100 ms until the monitor is done (it must
   * not get lost), answering resend requests meanwhile. */
  publish_state(info.steps, u_prev, safe);
  heartbeat("done", "");
  for (const double end = now(); !monitor_done && now() - end < 10.0;) {
    handle(0.02);
    if (now() - last_beat >= 0.1) {
      PUBLISH(feeddrive_drive_state_t, ch_state, &kept[info.steps % KEEP]);
      heartbeat("done", "");
      last_beat = now();
    }
  }
  fprintf(stderr, "drive_adapter: %lld steps, %lld missed deadlines, %lld rejected commands, %lld resends\n",
          (long long)info.steps, (long long)missed, (long long)rejected, (long long)resends);
  lcm_destroy(lc);
  return 0;
}
