#!/usr/bin/env bash
# feeddrive-fit speed and detection rate (not a timed test):
#   1. speed: a 10 s record at 1 kHz of scenarios/fit/truth_cogging.yaml (feeddrive-sim, the
#      measured position column), fitted with the whole vocabulary by the feeddrive-fit
#      executable against scenarios/fit/model.yaml, RUNS times; the median wall time is printed
#      (target < 60 s on one core);
#   2. the sweep (bench/fit_sweep.cpp): every effect hidden with seeded random parameters in
#      SEEDS closed-loop recordings each, and 2*SEEDS effect-free ones; prints detection rates.
# Usage: bench/fit_bench.sh [BUILD_DIR] [RUNS] [SEEDS]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
RUNS=${2:-3}
SEEDS=${3:-10}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
"$BUILD/bin/feeddrive-sim" scenarios/fit/truth_cogging.yaml --out "$TMP/truth" --no-plots --quiet
times=()
for r in $(seq "$RUNS"); do
  s=$(date +%s%N)
  taskset -c 0 "$BUILD/bin/feeddrive-fit" --scenario scenarios/fit/model.yaml --data "$TMP/truth/timeseries.csv" \
      --position-column x_measured --out "$TMP/fit$r" -q > "$TMP/fit$r.txt"
  e=$(date +%s%N)
  times+=("$(awk -v a="$s" -v b="$e" 'BEGIN { printf "%.3f", (b - a) / 1e9 }')")
  echo "run $r: $(printf '%.2f' "${times[-1]}") s: $(tail -n 2 "$TMP/fit$r.txt" | head -n 1)"
done
median() { printf '%s\n' "$@" | sort -g | awk '{ a[NR] = $1 } END { print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }
echo "feeddrive-fit on a 10 s, 1 kHz record, whole vocabulary, one core: median $(printf '%.2f' "$(median "${times[@]}")") s over $RUNS runs (target < 60 s)"
cat "$TMP/fit1.txt"
echo
echo "sweep: $SEEDS seeds per effect (10 s records)"
"$BUILD/bin/fit_sweep" "$SEEDS" 10
