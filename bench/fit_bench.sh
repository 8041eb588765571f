#!/usr/bin/env bash
# feeddrive-fit speed and detection rate on data it was not built against (not a timed test):
#   1. speed: a 25 s record at 1 kHz of the independent generator (tests/fit/drivegen: static
#      base friction, a grinding process described, a hidden constant force and cogging ripple),
#      fitted with the whole vocabulary (all 11 candidates eligible) by the feeddrive-fit
#      executable pinned to one core, RUNS times; prints the median wall time (target < 30 s);
#   2. the sweep (bench/fit_sweep.cpp): N seeded generator records (every effect alone, pairs,
#      effect-free), split over the cores; prints the rates the issue asks for.
# Usage: bench/fit_bench.sh [BUILD_DIR] [RUNS] [N] [SEED]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
RUNS=${2:-3}
N=${3:-120}
SEED=${4:-1}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
"$BUILD/bin/fd-drivegen" 8 "$TMP/rec" 25 constant_force,cogging_ripple grinding
times=()
for r in $(seq "$RUNS"); do
  s=$(date +%s%N)
  taskset -c 0 "$BUILD/bin/feeddrive-fit" --scenario "$TMP/rec/model.yaml" --data "$TMP/rec/data.csv" \
      --out "$TMP/fit$r" -q --no-plots > "$TMP/fit$r.txt"
  e=$(date +%s%N)
  times+=("$(awk -v a="$s" -v b="$e" 'BEGIN { printf "%.3f", (b - a) / 1e9 }')")
  echo "run $r: $(printf '%.2f' "${times[-1]}") s: $(tail -n 2 "$TMP/fit$r.txt" | head -n 1)"
done
median() { printf '%s\n' "$@" | sort -g | awk '{ a[NR] = $1 } END { print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }
echo "feeddrive-fit on a 25 s, 1 kHz record, whole vocabulary, one core: median $(printf '%.2f' "$(median "${times[@]}")") s over $RUNS runs (target < 30 s)"
cat "$TMP/fit1.txt"
echo
CORES=$(nproc)
echo "sweep: $N records of the independent generator (seed $SEED, 10 s each), $CORES shards"
for k in $(seq 0 $((CORES - 1))); do
  "$BUILD/bin/fit_sweep" "$N" "$SEED" "$k" "$CORES" > "$TMP/sweep$k.tsv" &
done
wait
cat "$TMP"/sweep*.tsv | sort -n > "$TMP/sweep.tsv"
awk -F'\t' '$4 == 0 { print "  miss: " $1 " hidden " $2 ", named " $3 (($7 != "-") ? ", " $7 : "") " (" $8 ")" }' "$TMP/sweep.tsv"
awk -F'\t' '
  { n++; right += $4; spur += $5
    if ($2 == "none") { free++; if ($3 != "none") named_free++ } }
  END {
    printf "named right (set and main parameters): %d of %d (%.1f %%)\n", right, n, 100 * right / n
    printf "with a spurious extra effect:          %d of %d (%.1f %%)\n", spur, n, 100 * spur / n
    printf "effect-free records naming an effect:  %d of %d (%.1f %%)\n", named_free, free, free ? 100 * named_free / free : 0
  }' "$TMP/sweep.tsv"
echo "fit time per record (2 records at a time on $CORES cores): median $(cut -f6 "$TMP/sweep.tsv" | sort -g | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }') s, max $(cut -f6 "$TMP/sweep.tsv" | sort -g | tail -n 1) s"
