#!/usr/bin/env bash
# feeddrive-study speed (issue 10, point 8; not a timed test): a study of CASES cases of the
# jerk-limited move at 10 kHz (scenarios/paper/smc_bl_jerk_limited.yaml: boundary-layer SMC,
# 15,000 control periods, mass drawn +-20 %) against its ideal time, measured in the same run:
#   one case = the median wall time of that scenario run alone, RUNS times before and RUNS times
#              after the study (feeddrive-sim's own timing of the run: summary.json wall_time_s,
#              which leaves out process start, loading and writing: the strictest ideal);
#   ideal    = CASES x one case / cores (nproc);
#   ratio    = the study's wall time (the whole feeddrive-study command: loading and resolving the
#              cases, the runs, results.csv, report.md and plots) / ideal   (target <= 1.2).
# It also measures what the machine gives: `cores` copies of the same case started at once (separate
# feeddrive-sim processes, RUNS rounds, before and after the study). On a quiet machine with free
# cores one copy among `cores` takes as long as one alone; on a shared one (other work on the cores,
# shared caches, a VM's vCPUs) it takes longer, and no runner can beat cases x that time / cores.
# The printed "machine" ratio and "ratio against the parallel ideal" tell the runner apart from it.
# With SERIAL > 0 it also runs a study of SERIAL cases with -j 1 against SERIAL x one case: the
# runner on one thread, which no other work on the second core can slow down.
# Run it alone: flock /tmp/feeddrive-bench.lock bash bench/study_bench.sh [BUILD_DIR] [CASES] [RUNS] [SERIAL]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
CASES=${2:-1000}
RUNS=${3:-5}
SERIAL=${4:-0}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
SCEN=$PWD/scenarios/paper/smc_bl_jerk_limited.yaml
CORES=$(nproc)
cat > "$TMP/bench.yaml" <<YAML
name: bench
base: $SCEN
families:
  - name: mass
    monte_carlo:
      draws: $CASES
      seed: 1
      parameters:
        - {key: plant.mass, distribution: uniform, low: 0.8, high: 1.2, scale: true}
YAML
one_case() {
  for r in $(seq "$RUNS"); do
    "$BUILD/bin/feeddrive-sim" "$SCEN" --out "$TMP/one" --no-plots --quiet
    jq -r .wall_time_s "$TMP/one/summary.json"
  done
}
# CORES copies of the case at once, RUNS rounds: one wall time per copy and round.
parallel_case() {
  for r in $(seq "$RUNS"); do
    for c in $(seq "$CORES"); do
      "$BUILD/bin/feeddrive-sim" "$SCEN" --out "$TMP/par$c" --no-plots --quiet &
    done
    wait
    for c in $(seq "$CORES"); do jq -r .wall_time_s "$TMP/par$c/summary.json"; done
  done
}
median() { sort -g | awk '{ a[NR] = $1 } END { print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }
one_case > "$TMP/one.txt"
parallel_case > "$TMP/par.txt"
s=$(date +%s%N)
"$BUILD/bin/feeddrive-study" "$TMP/bench.yaml" --out "$TMP/study" -q
e=$(date +%s%N)
if [ "$SERIAL" -gt 0 ]; then
  sed "s/draws: $CASES/draws: $SERIAL/" "$TMP/bench.yaml" > "$TMP/serial.yaml"
  s1=$(date +%s%N)
  "$BUILD/bin/feeddrive-study" "$TMP/serial.yaml" --out "$TMP/serial" -q -j 1
  e1=$(date +%s%N)
fi
one_case >> "$TMP/one.txt"
parallel_case >> "$TMP/par.txt"
t1=$(median < "$TMP/one.txt")
tp=$(median < "$TMP/par.txt")
wall=$(awk -v a="$s" -v b="$e" 'BEGIN { printf "%.3f", (b - a) / 1e9 }')
sum=$(jq -r .case_time_sum_s "$TMP/study/timing.json")
ok=$(awk -F, 'NR > 1 && $0 ~ /,true,/ { n++ } END { print n + 0 }' "$TMP/study/results.csv")
echo "one case (jerk-limited move, 10 kHz, 15,000 periods): median $(printf '%.4f' "$t1") s over $((2 * RUNS)) runs alone"
echo "study: $CASES cases ($ok ok) on $CORES cores: wall $(printf '%.2f' "$wall") s; sum of the cases' own times in the study $(printf '%.2f' "$sum") s"
echo "machine: one case among $CORES started at once: median $(printf '%.4f' "$tp") s over $((2 * RUNS * CORES)) runs"
awk -v n="$CASES" -v t="$t1" -v c="$CORES" -v w="$wall" -v s="$sum" -v p="$tp" 'BEGIN {
  ideal = n * t / c
  printf "ideal = cases x one case / cores = %d x %.4f / %d = %.2f s\n", n, t, c, ideal
  printf "ratio = wall / ideal = %.3f (target <= 1.2)\n", w / ideal
  printf "(wall / (sum of the cases'\'' own times / cores) = %.3f: the runner'\''s own overhead)\n", w / (s / c)
  printf "(machine = one case among %d at once / one case alone = %.3f; ratio against the parallel ideal cases x %.4f / %d: %.3f)\n", c, p / t, p, c, w / (n * p / c)
}'
if [ "$SERIAL" -gt 0 ]; then
  awk -v n="$SERIAL" -v t="$t1" -v a="$s1" -v b="$e1" 'BEGIN {
    w = (b - a) / 1e9
    printf "one thread: %d cases with -j 1: wall %.2f s against %d x one case = %.2f s: ratio %.3f\n", n, w, n, n * t, w / (n * t)
  }'
fi
