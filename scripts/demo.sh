#!/usr/bin/env bash
# Main job: installs, builds, runs the paper's closed-loop studies and prints a summary table.
# Results (timeseries.csv, summary.json, PNG plots) go to ${OUT:-out/demo}/<scenario>/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
BUILD_DIR=${BUILD_DIR:-build}
OUT=${OUT:-out/demo}
mkdir -p "$OUT"
SCENARIOS=(smc_sine smc_accel_limited smc_jerk_limited smc_ramp_all_forces smc_bl_jerk_limited beyond_jerk_limited)
printf '\n%-24s %12s %14s %12s %12s %10s\n' scenario "max|e| [um]" "rms e [um]" "u_min [V]" "u_max [V]" "wall [s]"
for s in "${SCENARIOS[@]}"; do
  f=scenarios/paper/$s.yaml
  [ -f "$f" ] || continue
  "$BUILD_DIR/bin/feeddrive-sim" "$f" --out "$OUT/$s" --quiet
  jq -r --arg s "$s" '[$s, (.position_error_max_abs_m*1e6), (.position_error_rms_m*1e6), .control_min, .control_max, .wall_time_s]
      | "\(.[0])\t\(.[1])\t\(.[2])\t\(.[3])\t\(.[4])\t\(.[5])"' "$OUT/$s/summary.json" |
    awk -F'\t' '{printf "%-24s %12.4g %14.4g %12.4g %12.4g %10.2f\n", $1, $2, $3, $4, $5, $6}'
done
echo
echo "plots and data: $OUT/<scenario>/{position,velocity_error,control,forces}.png, timeseries.csv, summary.json"

# The multi-process service on the same scenario: four LCM processes in lockstep, in a private
# network namespace when one can be made (scripts/netns-run.sh), must give the same bytes.
s=smc_bl_jerk_limited
echo
echo "multi-process lockstep run of $s (feeddrive-launch: plant, controller, trajectory, monitor):"
if scripts/netns-run.sh "$BUILD_DIR/bin/feeddrive-launch" "scenarios/paper/$s.yaml" --out "$OUT/${s}_lcm" --no-plots -q; then
  if cmp -s "$OUT/$s/timeseries.csv" "$OUT/${s}_lcm/timeseries.csv"; then verdict="identical to feeddrive-sim's"; else verdict="DIFFERS from feeddrive-sim's"; fi
  jq -r --arg v "$verdict" '"  \(.steps) steps at \(.lockstep.steps_per_second | floor) steps/s, state->command p50 \(.lockstep.latency_us.state_to_command.p50) us; timeseries.csv " + $v' \
    "$OUT/${s}_lcm/summary.json"
  echo "  results: $OUT/${s}_lcm/"
else
  echo "  the multi-process run failed (no multicast route? see docs/lcm-contract.md); the in-process results above stand"
fi
