#!/usr/bin/env bash
# A robustness study of the example controller plugin (examples/plugin/smc_bl.c, built in-tree by
# examples/CMakeLists.txt as <build>/examples/plugin/libfd_example_smc_bl.so) against the same
# study of the built-in boundary-layer sliding-mode law (issue 25, point 5; docs/performance.md): the paper's jerk-limited move at
# 10 kHz (15,000 periods per case), CASES Monte Carlo plants (mass +-20 %, Fs/Fc and sigma0/sigma1
# +-30 %, seed 1), all cores. ROUNDS rounds, each runs both studies in turn (alternating which goes
# first); per study the wall time and the CPU time (user + system, /usr/bin/time) of the whole
# feeddrive-study command, and the sum of the cases' own times (timing.json). The CPU time is the
# figure to quote on a shared machine (other work there stretches wall times, not CPU times). Prints the medians and the ratio plugin / built-in (goal <= 1.10), and
# checks that both studies' results.csv agree in every metric (the same law, bit for bit).
#   flock /tmp/feeddrive-bench.lock bash bench/plugin_study_bench.sh [BUILD_DIR] [CASES] [ROUNDS]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
CASES=${2:-200}
ROUNDS=${3:-5}
LIB=$PWD/$BUILD/examples/plugin/libfd_example_smc_bl.so
for f in "$BUILD/bin/feeddrive-study" "$LIB"; do
  [ -e "$f" ] || { echo "plugin_study_bench: $f is missing (cmake --build $BUILD --target feeddrive-study fd_example_smc_bl)"; exit 2; }
done
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
SCEN=$PWD/scenarios/paper/smc_bl_jerk_limited.yaml
study() {  # NAME CONTROLLER-ENTRY
  cat > "$TMP/$1.yaml" << YAML
name: $1
base: $SCEN
controllers:
  - $2
families:
  - name: monte_carlo
    monte_carlo:
      draws: $CASES
      seed: 1
      parameters:
        - {key: plant.mass, distribution: uniform, low: 0.8, high: 1.2, scale: true}
        - {keys: [plant.friction.static_force, plant.friction.coulomb_force], distribution: uniform, low: 0.7, high: 1.3, scale: true}
        - {keys: [plant.friction.bristle_stiffness, plant.friction.bristle_damping], distribution: uniform, low: 0.7, high: 1.3, scale: true}
YAML
}
study builtin "{name: smc_bl, scenario: $SCEN}"
study plugin "{name: smc_bl, controller: {type: plugin, library: $LIB, parameters: {eta: 5.0, k: 10.0, lambda: 50.0, switching: sat, boundary_layer: 5.0e-4}}}"
: > "$TMP/times"
run() {  # NAME ROUND
  rm -rf "$TMP/out_$1"
  local s e
  s=$(date +%s%N)
  /usr/bin/time -f "%U %S" -o "$TMP/cpu" "$BUILD/bin/feeddrive-study" "$TMP/$1.yaml" --out "$TMP/out_$1" --no-plots -q
  e=$(date +%s%N)
  echo "$1 $(awk -v a="$s" -v b="$e" 'BEGIN { printf "%.4f", (b - a) / 1e9 }') $(jq -r .case_time_sum_s "$TMP/out_$1/timing.json") $(awk '{ print $1 + $2 }' "$TMP/cpu")" >> "$TMP/times"
}
for r in $(seq "$ROUNDS"); do
  if [ $((r % 2)) = 1 ]; then run builtin "$r"; run plugin "$r"; else run plugin "$r"; run builtin "$r"; fi
done
python3 - "$TMP/times" "$TMP/out_builtin/results.csv" "$TMP/out_plugin/results.csv" "$CASES" "$(nproc)" << 'PY'
import csv, statistics, sys
t = {}
for line in open(sys.argv[1]):
    n, wall, cases, cpu = line.split()
    t.setdefault(n, []).append((float(wall), float(cases), float(cpu)))
a, b = list(csv.DictReader(open(sys.argv[2]))), list(csv.DictReader(open(sys.argv[3])))
diff = [k for ra, rb in zip(a, b) for k in ra if k not in ("hash",) and ra[k] != rb[k]]
print(f"{sys.argv[4]} cases per study, {len(t['builtin'])} rounds, {sys.argv[5]} cores; results identical: {not diff and len(a) == len(b)}")
for what, i in (("CPU time of feeddrive-study", 2), ("wall time of feeddrive-study", 0), ("sum of the cases' own times", 1)):
    mb = statistics.median(x[i] for x in t["builtin"])
    mp = statistics.median(x[i] for x in t["plugin"])
    print(f"{what:30s} built-in {mb:8.3f} s  plugin {mp:8.3f} s  ratio plugin / built-in {mp / mb:.3f} (goal <= 1.10)")
print(f"per case (CPU / cases): built-in {statistics.median(x[2] for x in t['builtin']) / int(sys.argv[4]) * 1e3:.2f} ms, "
      f"plugin {statistics.median(x[2] for x in t['plugin']) / int(sys.argv[4]) * 1e3:.2f} ms")
PY
