#!/usr/bin/env bash
# Real time at 10 kHz: the paper's beyond_jerk_limited move (15,000 steps of 100 us) with
# feeddrive-launch --realtime --cpus 0, ROUNDS times (default 5). Prints, per run and as medians:
# the deadline misses (target < 15, i.e. < 0.1 %), the plant's own overruns, the state -> command latency p50/p99 and the
# period-start lateness p99 (from summary.json's latency_histogram_us), the max position error,
# and how the plant was scheduled (SCHED_FIFO, or why not). Timing-sensitive: run it on a quiet
# machine, in a private network namespace:
#   scripts/netns-run.sh bench/realtime_bench.sh [BUILD_DIR] [ROUNDS] [extra feeddrive-launch options]
# The machine's own count in the same invocation: right before each run, cyclictest (rt-tests:
# SCHED_FIFO 80, mlockall, a 100 us interval, 15,000 wake-ups on the run's CPUs) counts the timer
# wake-ups later than 50 us; the bench prints feeddrive's deadline misses over that count per round
# and the median ratio (goal: <= 2, the chain has two wake-ups a period: the plant's timer and the
# controller's receive). CPUS=0 (default) pins the run and cyclictest to CPU 0; CPUS=0,1 gives
# both cores (cyclictest then runs one thread per core and its count is the sum).
# ADAPTER=PATH runs that program (examples/c/drive_adapter.c, built as tests/service/hil_test.sh
# does: liblcm's receive thread and pipe) as the plant, at SCHED_FIFO 80 on CPUS, with the launcher's
# --external plant, on SCEN (default here scenarios/robustness/robust_smc.yaml: 10 kHz, observers):
# what a participant that receives with liblcm gets (docs/lcm-contract.md, "Receiving in batches").
# ISOLATE=1 (root, cgroup v1 cpuset) moves every other task of the machine off CPUS for the
# bench's duration (a cpuset "feeddrive-others" on the remaining CPUs; kernel threads bound to
# a CPU stay), and puts them back at the end: what an isolated core gives the same chain
# (docs/lcm-contract.md, "An isolated core"). OFF_PATH_CPUS=LIST passes --off-path-cpus LIST: the
# monitor and the trajectory there, the plant and controller on CPUS.
# The library's own floor in the same invocation: right after cyclictest, bench/lcm_pingpong_raw.c
# (liblcm only: lcm_publish, lcm_handle) runs the same exchange with the plant's rule: ping k at
# k*T on an absolute timer, pong k due T - guard later (guard = min(T/5, 25 us), as
# service/src/plant_node.cpp), then WORK_US (default 16 us, the paper plant's integration per step)
# of work; client at SCHED_FIFO 81 and server at 80 on CPUS, plus two listeners (the monitor's and
# the trajectory's sockets: each datagram is copied to four sockets) at 79 and 78 on CPUS, or on
# OFF_PATH_CPUS when given. It prints the raw misses, raw / machine and feeddrive / raw: whether a
# miss comes from the chain or from liblcm and the kernel on this machine.
# The plant and the controller hold the CPU wake-up latency at 0 (/dev/cpu_dma_latency, as
# cyclictest does). LATENCY_HOLD=alternate runs the odd rounds with it and the even ones without
# (FEEDDRIVE_CPU_LATENCY_HOLD=0) and prints the medians of each: what the hold changes, same run.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
ROUNDS=${2:-5}
shift $(( $# < 2 ? $# : 2 ))
URL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304'
SCEN=${SCEN:-scenarios/paper/beyond_jerk_limited.yaml}
ADAPTER=${ADAPTER:-}
if [ -n "$ADAPTER" ] && [ "$SCEN" = scenarios/paper/beyond_jerk_limited.yaml ]; then SCEN=scenarios/robustness/robust_smc.yaml; fi
TMP=$(mktemp -d)
trap 'jobs -p | xargs -r kill 2>/dev/null || true; rm -rf "$TMP"' EXIT
median() { printf '%s\n' "$@" | sort -g | awk '{ a[NR] = $1 } END { print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }
# p99 of a histogram (bins of bin_us, then the overflow) as the upper edge of its bin.
hist_p99='def p99(h; b): (h.samples * 0.99) as $t | reduce range(0; h.counts | length) as $i ({s: 0, v: null};
  .s += h.counts[$i] | if .v == null and .s >= $t then .v = ($i + 1) * b else . end) | (.v // "overflow");'
CPUS=${CPUS:-0}
command -v cyclictest > /dev/null || { echo "cyclictest (rt-tests) not installed: scripts/install-deps.sh adds it"; exit 2; }
# Wake-ups later than 50 us in 15,000 of cyclictest at 100 us on CPUS (histogram bins > 50 plus
# its overflows).
machine_late() {
  local n; n=$(echo "$CPUS" | tr ',' '\n' | wc -l)
  cyclictest -m -p 80 -i 100 -a "$CPUS" -t "$n" -l 15000 -q -h 1000 2> /dev/null |
    awk '/^[0-9]+ / { us = $1 + 0; for (i = 2; i <= NF; ++i) if (us > 50) late += $i } /Histogram Overflows/ { for (i = 4; i <= NF; ++i) late += $i } END { print late + 0 }'
}
ISOLATE=${ISOLATE:-}
CPUSET=/sys/fs/cgroup/cpuset
if [ -n "$ISOLATE" ]; then
  ALL=$(cat "$CPUSET/cpuset.cpus")
  REST=$(python3 -c "
import sys
def parse(s):
    out = set()
    for part in s.split(','):
        a, _, b = part.partition('-')
        out.update(range(int(a), int(b or a) + 1))
    return out
rest = sorted(parse(sys.argv[1]) - parse(sys.argv[2]))
print(','.join(map(str, rest)))" "$ALL" "$CPUS")
  [ -n "$REST" ] || { echo "ISOLATE: CPUS=$CPUS leaves no CPU for the rest of the machine ($ALL)"; exit 2; }
  [ -w "$CPUSET/tasks" ] || { echo "ISOLATE: needs root and a cgroup v1 cpuset at $CPUSET"; exit 2; }
  OTHERS=$CPUSET/feeddrive-others
  mkdir -p "$OTHERS"
  echo "$REST" > "$OTHERS/cpuset.cpus"
  cat "$CPUSET/cpuset.mems" > "$OTHERS/cpuset.mems"
  restore() {
    while read -r t; do echo "$t" > "$CPUSET/tasks" 2> /dev/null || true; done < "$OTHERS/tasks"
    rmdir "$OTHERS" 2> /dev/null || true
  }
  trap 'restore; jobs -p | xargs -r kill 2>/dev/null || true; rm -rf "$TMP"' EXIT
  # Several passes: a task forked during a pass by a parent not yet moved is still in the root
  # cpuset (a parallel build forks a compiler every few ms); the passes end when one moves none.
  moved=0
  for _pass in 1 2 3 4 5; do
    n=0
    while read -r t; do
      [ "$t" = $$ ] && continue  # this bench (and what it starts) stays where it can reach CPUS
      echo "$t" > "$OTHERS/tasks" 2> /dev/null && n=$((n + 1)) || true
    done < "$CPUSET/tasks"
    moved=$((moved + n))
    [ "$n" -le 3 ] && break  # the pass's own short-lived helpers (the while's subshells)
  done
  echo "ISOLATE: $moved tasks moved to CPUs $REST for the bench; CPUs $CPUS keep the run, cyclictest and per-CPU kernel threads"
fi
WORK_US=${WORK_US:-16}
# Misses of the raw liblcm exchange with the plant's rule (see above), one round.
raw_floor() {
  local tag=$1 lst=${OFF_PATH_CPUS:-$CPUS} pids=() out
  taskset -c "$lst" chrt -f 79 "$BUILD/bin/lcm-pingpong-raw" listen "$URL" "$tag" & pids+=($!)
  taskset -c "$lst" chrt -f 78 "$BUILD/bin/lcm-pingpong-raw" listen "$URL" "$tag" & pids+=($!)
  taskset -c "$CPUS" chrt -f 80 "$BUILD/bin/lcm-pingpong-raw" server "$URL" "$tag" & pids+=($!)
  sleep 0.2  # the server's first pong is awaited by the client's warm-up; this only spares it resends
  out=$(taskset -c "$CPUS" chrt -f 81 "$BUILD/bin/lcm-pingpong-raw" client "$URL" "$tag" 15000 100 20 "$WORK_US")
  kill "${pids[@]}" 2> /dev/null || true  # a listener that lost the stop ping would wait 30 s
  wait "${pids[@]}" 2> /dev/null || true
  echo "$out" | awk '/paced_misses/ { print $2 }'
}
misses=(); overruns=(); lates=(); ratios=(); raws=(); raw_ratios=(); chain_ratios=(); held_misses=(); held_ratios=(); free_misses=(); free_ratios=()
for r in $(seq "$ROUNDS"); do
  late=$(machine_late)
  lates+=("$late")
  raw=$(raw_floor "RAW$r")
  raws+=("$raw")
  raw_ratios+=("$(awk -v m="$raw" -v l="$late" 'BEGIN { printf "%.2f", m / (l > 0 ? l : 1) }')")
  hold=held
  if [ "${LATENCY_HOLD:-}" = alternate ] && [ $((r % 2)) = 0 ]; then hold="not held"; export FEEDDRIVE_CPU_LATENCY_HOLD=0
  else unset FEEDDRIVE_CPU_LATENCY_HOLD; fi
  ext=()
  if [ -n "$ADAPTER" ]; then
    taskset -c "$CPUS" chrt -f 80 "$ADAPTER" --url "$URL" --prefix "RT$r" 2> "$TMP/adapter$r.err" &
    ext=(--external plant)
  fi
  off=()
  [ -n "${OFF_PATH_CPUS:-}" ] && off=(--off-path-cpus "$OFF_PATH_CPUS")
  "$BUILD/bin/feeddrive-launch" "$SCEN" --out "$TMP/rt$r" --no-plots --realtime --cpus "$CPUS" "${off[@]}" --lcm-url "$URL" "${ext[@]}" \
      --prefix "RT$r" "$@" 2> "$TMP/rt$r.err" || true
  [ -n "$ADAPTER" ] && { wait || true; }
  sched=$( (grep -o "plant: real time: [^,]*" "$TMP/rt$r.err" || true) | head -n 1 | sed 's/plant: real time: //')
  sched=${sched:-"SCHED_FIFO granted (no warning from the plant)"}
  j=$TMP/rt$r/summary.json
  [ -f "$j" ] || { tail -3 "$TMP/rt$r.err"; echo "round $r: no summary"; continue; }
  misses+=("$(jq -r .lockstep.deadline_misses "$j")")
  overruns+=("$(jq -r .lockstep.plant_overruns "$j")")
  ratios+=("$(awk -v m="${misses[-1]}" -v l="$late" 'BEGIN { printf "%.2f", m / (l > 0 ? l : 1) }')")
  chain_ratios+=("$(awk -v m="${misses[-1]}" -v l="$raw" 'BEGIN { printf "%.2f", m / (l > 0 ? l : 1) }')")
  if [ "$hold" = held ]; then held_misses+=("${misses[-1]}"); held_ratios+=("${ratios[-1]}")
  else free_misses+=("${misses[-1]}"); free_ratios+=("${ratios[-1]}"); fi
  echo "round $r (CPU wake-up latency $hold): machine (cyclictest, CPUs $CPUS): $late of 15000 wake-ups later than 50 us; feeddrive misses / machine = ${ratios[-1]}; raw liblcm (same rule) $raw misses, raw / machine = ${raw_ratios[-1]}, feeddrive / raw = ${chain_ratios[-1]}"
  echo "round $r: $(jq -r "$hist_p99"' .lockstep as $l | "\($l.deadline_misses) of \($l.steps_expected) deadlines missed, \($l.plant_overruns) plant overruns; state->command p50 \($l.latency_us.state_to_command.p50) us, p99 \($l.latency_us.state_to_command.p99) us; period-start lateness p99 <= \(p99($l.latency_histogram_us.period_start_lateness; $l.latency_histogram_us.bin_us)) us"' "$j"); max |e| $(jq -r "(.position_error_max_abs_m // .measured_position_error_max_abs_m)" "$j") m (measured where no true state); $sched"
done
echo "median deadline misses: $(median "${misses[@]}") of 15000 (target < 15, 0.1 %); median plant overruns (periods the plant itself started more than its guard late): $(median "${overruns[@]}")"
echo "machine (cyclictest on CPUs $CPUS): median $(median "${lates[@]}") of 15000 wake-ups later than 50 us; RATIO feeddrive misses / machine's late wake-ups: median $(median "${ratios[@]}") (per round: ${ratios[*]}; goal <= 2)"
echo "raw liblcm, the plant's rule, same CPUs (the library's floor): median $(median "${raws[@]}") of 15000 missed; RATIO raw / machine: median $(median "${raw_ratios[@]}") (per round: ${raw_ratios[*]}); RATIO feeddrive / raw: median $(median "${chain_ratios[@]}") (per round: ${chain_ratios[*]})"
if [ "${#free_misses[@]}" -gt 0 ] && [ "${#held_misses[@]}" -gt 0 ]; then
  echo "CPU wake-up latency held at 0: median misses $(median "${held_misses[@]}") (${held_misses[*]}), ratio $(median "${held_ratios[@]}"); not held: median misses $(median "${free_misses[@]}") (${free_misses[*]}), ratio $(median "${free_ratios[@]}")"
fi
