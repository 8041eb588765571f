// fd-steal-probe: how much CPU time a machine takes away from a real-time process, with no LCM,
// no CVODE and no feeddrive code (docs/lcm-contract.md, "Real time").
//
// It pins itself to CPU 0, asks for SCHED_FIFO 80 and mlockall (as the real-time plant does), and
// reads CLOCK_MONOTONIC in a tight loop for SECONDS (default 0.9 s: under the kernel's RT
// throttling budget of 950 ms per second). Every gap between two consecutive reads is time the
// loop did not run: an interrupt the guest handled, or time a hypervisor gave to someone else.
// It prints how many gaps exceed 10, 20, 40 and 100 us, and the largest. At 10 kHz a period is
// 100 us and a command must arrive 25 us before its end, so a machine that steals more than
// ~40 us in more than 0.1 % of periods cannot meet the real-time bench's target whatever the
// processes do. Compare the count with the local timer interrupts /proc/interrupts shows for CPU 0
// over the same time: gaps the guest took no interrupt for were taken by the host.
//
// Usage: fd-steal-probe [SECONDS]     (root, or CAP_SYS_NICE, for SCHED_FIFO; says so if not)
#define _GNU_SOURCE
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <time.h>

static long long now_ns(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec * 1000000000LL + t.tv_nsec;
}

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? atof(argv[1]) : 0.9;
  if (!(seconds > 0.0 && seconds <= 60.0)) {
    fprintf(stderr, "fd-steal-probe: SECONDS = %s: must be in (0, 60]\n", argv[1]);
    return 2;
  }
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(0, &set);
  sched_setaffinity(0, sizeof set, &set);
  struct sched_param p = {.sched_priority = 80};
  const int fifo = sched_setscheduler(0, SCHED_FIFO, &p) == 0;
  if (!fifo) fprintf(stderr, "fd-steal-probe: SCHED_FIFO not permitted: normal scheduling (expect more gaps)\n");
  mlockall(MCL_CURRENT | MCL_FUTURE);
  const long long start = now_ns(), end = start + (long long)(seconds * 1e9);
  long long last = start, worst = 0;
  long over10 = 0, over20 = 0, over40 = 0, over100 = 0;
  for (;;) {
    const long long t = now_ns(), gap = t - last;
    last = t;
    if (t > end) break;
    over10 += gap > 10000;
    over20 += gap > 20000;
    over40 += gap > 40000;
    over100 += gap > 100000;
    if (gap > worst) worst = gap;
  }
  const double periods = seconds * 1e4;  // 100-us periods of a 10 kHz loop in the same time
  printf(
      "%s, CPU 0, %.2f s: gaps > 10 us %ld, > 20 us %ld, > 40 us %ld (%.2f %% of 100-us periods), > 100 us %ld; "
      "largest %.1f us\n",
      fifo ? "SCHED_FIFO 80" : "normal scheduling", seconds, over10, over20, over40, 100.0 * over40 / periods, over100,
      worst / 1e3);
  return 0;
}
