#!/usr/bin/env bash
# Where a lockstep step's time goes, measured with perf: the four-process run of the paper's
# boundary-layer jerk-limited move (15,000 steps) pinned to CPU 0 (feeddrive-launch --cpus 0, the
# placement where every microsecond of a step is spent one after the other on one core), sampled
# on CPU 0 by perf (cpu-clock, 10 kHz) for the whole run. For each process and object (its own
# code, CVODE, liblcm, libc/libm/libstdc++, the kernel) it prints the CPU time per step
# (samples / rate / steps) and, from the monitor's steps/s, the wall time per step; what is left
# is the CPU idle, i.e. waiting for a wake-up. Process start-up and the end of the run are
# included in the CPU times (a few ms against the run's ~1 s).
#   scripts/netns-run.sh bash bench/step_profile.sh [BUILD_DIR] [ROUNDS]
# Needs perf (linux-perf) and permission to sample a CPU (root, or perf_event_paranoid <= 0).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
ROUNDS=${2:-3}
URL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304'
SCEN=scenarios/paper/smc_bl_jerk_limited.yaml
RATE=10000
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
command -v perf > /dev/null || { echo "step_profile: perf is not installed (apt-get install linux-perf)"; exit 2; }
for r in $(seq "$ROUNDS"); do
  perf record -q -C 0 -F "$RATE" -e cpu-clock -o "$TMP/perf$r.data" -- \
      "$BUILD/bin/feeddrive-launch" "$SCEN" --out "$TMP/run$r" --no-plots -q --lcm-url "$URL" --prefix "SP$r" --cpus 0 \
      > /dev/null 2>&1
  sps=$(jq -r .lockstep.steps_per_second "$TMP/run$r/summary.json")
  steps=$(jq -r .lockstep.steps_expected "$TMP/run$r/summary.json")
  # comm, dso, samples -> us per step; grouped into the components of a step.
  perf report -i "$TMP/perf$r.data" --stdio --sort comm,dso -F sample,comm,dso 2> /dev/null |
    awk -v rate="$RATE" -v steps="$steps" -v sps="$sps" -v round="$r" '
      /^#/ || NF < 3 { next }
      {
        n = $1; comm = $2; dso = $3
        if (comm ~ /^feeddrive-plan/) p = "plant"; else if (comm ~ /^feeddrive-cont/) p = "controller";
        else if (comm ~ /^feeddrive-traj/) p = "trajectory"; else if (comm ~ /^feeddrive-moni/) p = "monitor";
        else if (comm ~ /^swapper/) p = "idle"; else p = "other processes";
        if (p == "idle") what = "";
        else if (dso ~ /kernel/) what = "kernel (UDP send/receive, poll, scheduling)";
        else if (dso ~ /sundials/) what = "CVODE";
        else if (dso ~ /liblcm/) what = "liblcm";
        else if (dso ~ /^(libc|libm|libstdc|ld-linux)/) what = "libc/libm/libstdc++";
        else if (dso ~ /^libcrypto/) what = "libcrypto";
        else what = "own code";
        key = p (what == "" ? "" : ": " what)
        us[key] += n / rate * 1e6 / steps; tot[p] += n / rate * 1e6 / steps
      }
      END {
        step = 1e6 / sps
        printf "round %d: %.0f steps/s, %.2f us per step (wall)\n", round, sps, step
        for (k in us) if (us[k] >= 0.05) printf "  %-60s %7.2f us/step\n", k, us[k] | "sort -k1,1"
        close("sort -k1,1")
        busy = 0; for (p in tot) if (p != "idle") { busy += tot[p]; printf "  total %-54s %7.2f us/step\n", p, tot[p] }
        printf "  CPU busy %.2f us/step; sampled idle %.2f us/step\n", busy, tot["idle"]
      }'
  # The kernel part of the two processes on the step's critical path, by function (top 12).
  for comm in feeddrive-plant feeddrive-contr; do
    echo "  $comm, kernel functions [us/step]:"
    perf report -i "$TMP/perf$r.data" --stdio --comms "$comm" --dsos '[kernel.kallsyms]' --sort sym -F sample,sym 2> /dev/null |
      awk -v rate="$RATE" -v steps="$steps" '/^#/ || NF < 2 { next } { printf "    %6.2f %s\n", $1 / rate * 1e6 / steps, $NF }' | sort -rn | head -n 12
  done
done
