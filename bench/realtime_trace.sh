#!/usr/bin/env bash
# Who delays the plant in a real-time run (issue 21, "a perf or ftrace of the late periods"): one
# round of bench/realtime_bench.sh on CPUS (default 0) under `perf sched record -C CPUS`, then
# bench/late_wakeups.py on the trace: each task's share of the CPU during the run, and for every
# wake-up of the plant that waited more than 20 us to run, the task that ran before it. Run it in
# a private network namespace, as root (perf and the bench's ISOLATE need it):
#   scripts/netns-run.sh bash bench/realtime_trace.sh [BUILD_DIR]
# The environment of realtime_bench.sh applies (ISOLATE=1, OFF_PATH_CPUS=1, ...). perf is not in
# scripts/install-deps.sh: this is an investigation tool (apt-get install linux-perf).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
CPUS=${CPUS:-0}
command -v perf > /dev/null || { echo "perf not installed (apt-get install linux-perf)"; exit 2; }
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
perf sched record -C "$CPUS" -o "$TMP/perf.data" -- sleep 1000 > "$TMP/perf.out" 2>&1 &
perf_pid=$!
sleep 1
CPUS=$CPUS bash bench/realtime_bench.sh "$BUILD" 1 | grep -E "^round|ISOLATE" || true
kill -INT "$perf_pid" 2> /dev/null || true
wait "$perf_pid" 2> /dev/null || true
perf sched timehist -i "$TMP/perf.data" -C "${CPUS%%,*}" > "$TMP/timehist.txt" 2> /dev/null
python3 bench/late_wakeups.py "$TMP/timehist.txt" 20
