#!/usr/bin/env bash
# Long runs (issue 11), measured in one run:
#   1. speed: the 80 s run of scenarios/paper/beyond_jerk_limited.yaml (800,000 steps), the
#      whole `feeddrive-sim` with plots against the simulation's own time (bench/sim_only.cpp:
#      the same loop, records discarded), ROUNDS rounds alternating, medians and their ratio
#      (goal <= 1.5); also the CPU time (user + system) of both, since feeddrive-sim writes the
#      CSV on a second thread: the CPU ratio is what the output costs on one core;
#   2. memory: peak RSS (/usr/bin/time -v, "Maximum resident set size") of the whole
#      `feeddrive-sim` with plots at 1e5, 1e6 and 1e7 steps (10, 100, 1000 s), every row written,
#      with the time feeddrive-sim reports for the plots.
# Usage: flock /tmp/feeddrive-bench.lock bench/long_run_bench.sh [BUILD_DIR] [ROUNDS]
# Needs about 3 GB of free disk for the 1e7-step timeseries.csv (removed at the end).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
ROUNDS=${2:-3}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
median() { printf '%s\n' "$@" | sort -g | awk '{ a[NR] = $1 } END { print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }
scenario() {  # scenario DURATION -> path of beyond_jerk_limited with that duration
  sed "s/^duration: 1.5 /duration: $1 /" scenarios/paper/beyond_jerk_limited.yaml > "$TMP/long_$1.yaml"
  grep -q "^duration: $1 " "$TMP/long_$1.yaml" || { echo "could not set the duration" >&2; exit 1; }
  echo "$TMP/long_$1.yaml"
}
# wall_cpu COMMAND...: "WALL CPU" in seconds (CPU = user + system, every thread)
wall_cpu() { /usr/bin/time -f "%e %U %S" "$@" 2>&1 >/dev/null | tail -1 | awk '{ printf "%s %.2f\n", $1, $2 + $3 }'; }

s80=$(scenario 80)
sims=() wholes=() sim_cpu=() whole_cpu=()
for r in $(seq "$ROUNDS"); do
  read -r _ c < <(wall_cpu "$BUILD/bin/fd-sim-only" "$s80")
  sims+=("$("$BUILD/bin/fd-sim-only" "$s80" | awk '{ print $2 }')")  # its own loop time, without start-up
  sim_cpu+=("$c")
  rm -rf "$TMP/out80"
  read -r w c < <(wall_cpu "$BUILD/bin/feeddrive-sim" "$s80" --out "$TMP/out80" -q)
  wholes+=("$w") whole_cpu+=("$c")
  echo "round $r: simulation alone ${sims[-1]} s (CPU ${sim_cpu[-1]} s), whole feeddrive-sim with plots ${wholes[-1]} s (CPU ${whole_cpu[-1]} s)"
done
ms=$(median "${sims[@]}"); mw=$(median "${wholes[@]}")
mcs=$(median "${sim_cpu[@]}"); mcw=$(median "${whole_cpu[@]}")
echo "80 s run (800000 steps): median simulation alone $ms s, median whole feeddrive-sim with plots $mw s"
awk -v w="$mw" -v s="$ms" 'BEGIN { printf "ratio whole / simulation: %.3f (goal <= 1.5)\n", w / s }'
awk -v w="$mcw" -v s="$mcs" 'BEGIN { printf "CPU time: simulation alone %.2f s, whole %.2f s, ratio %.3f (the output'"'"'s cost on one core)\n", s, w, w / s }'
echo "timeseries.csv of the 80 s run: $(du -m "$TMP/out80/timeseries.csv" | cut -f1) MB"

for d in 10 100 1000; do
  s=$(scenario $d)
  rm -rf "$TMP/mem"
  /usr/bin/time -v "$BUILD/bin/feeddrive-sim" "$s" --out "$TMP/mem" > "$TMP/time.txt" 2>&1
  rss=$(awk -F: '/Maximum resident set size/ { gsub(/ /, "", $2); print $2 }' "$TMP/time.txt")
  el=$(awk '/Elapsed \(wall clock\)/ { print $NF }' "$TMP/time.txt")
  plot=$(sed -n 's/.*plots drawn in \([0-9.]*\) s.*/\1/p' "$TMP/time.txt")
  steps=$(jq -r .steps "$TMP/mem/summary.json")
  echo "steps $steps: peak RSS $((rss / 1024)) MB, wall $el, plots $plot s, timeseries.csv $(du -m "$TMP/mem/timeseries.csv" | cut -f1) MB"
done
