#!/usr/bin/env bash
# Main job: installs, builds, and runs the multi-process demo: the paper's closed-loop studies,
# each as four LCM processes in lockstep (feeddrive-launch: plant, controller, trajectory,
# monitor) inside a private network namespace when one can be made (scripts/netns-run.sh; else
# the host loopback with ttl=0). Prints a summary table and writes plots; checks each run is
# byte-identical to the in-process feeddrive-sim; then the model-discrepancy walk-through
# (feeddrive-fit, docs/fit.md).
# Results go to ${OUT:-out/demo}/<scenario>/ (timeseries.csv, summary.json, PNG plots).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
BUILD_DIR=${BUILD_DIR:-build}
BIN=$BUILD_DIR/bin
OUT=${OUT:-out/demo}
mkdir -p "$OUT"
SCENARIOS=(smc_sine smc_accel_limited smc_jerk_limited smc_ramp_all_forces smc_bl_jerk_limited beyond_jerk_limited)
failed=0
echo
echo "multi-process lockstep runs (plant, controller, trajectory, monitor over LCM):"
printf '%-22s %8s %11s %11s %9s %9s %10s %10s\n' scenario steps "max|e| um" "rms e um" "u_min V" "u_max V" "steps/s" "= sim?"
for s in "${SCENARIOS[@]}"; do
  f=scenarios/paper/$s.yaml
  if ! scripts/netns-run.sh "$BIN/feeddrive-launch" "$f" --out "$OUT/$s" -q 2> "$OUT/$s.launch.log"; then
    echo "$s: the multi-process run failed (see $OUT/$s.launch.log)"
    failed=1
    continue
  fi
  "$BIN/feeddrive-sim" "$f" --out "$OUT/sim/$s" --no-plots --quiet
  same=$(cmp -s "$OUT/$s/timeseries.csv" "$OUT/sim/$s/timeseries.csv" && echo identical || echo DIFFERS)
  [ "$same" = identical ] || failed=1
  jq -r --arg s "$s" --arg same "$same" \
      '[$s, .steps, .position_error_max_abs_m*1e6, .position_error_rms_m*1e6, .control_min, .control_max,
        .lockstep.steps_per_second, $same] | map(tostring) | join("\t")' "$OUT/$s/summary.json" |
    awk -F'\t' '{printf "%-22s %8d %11.4g %11.4g %9.3g %9.3g %10.0f %10s\n", $1, $2, $3, $4, $5, $6, $7, $8}'
done
echo "plots and data: $OUT/<scenario>/{position,velocity_error,control,forces}.png, timeseries.csv, summary.json"

echo
echo "model-discrepancy walk-through (docs/fit.md): a drive with a hidden 15 N force and 4 N cogging ripple"
"$BIN/feeddrive-sim" scenarios/fit/truth_cogging.yaml --out "$OUT/fit_truth" --no-plots --quiet
"$BIN/feeddrive-fit" --scenario scenarios/fit/model.yaml --data "$OUT/fit_truth/timeseries.csv" \
    --position-column x_measured --out "$OUT/fit" -q
echo "report: $OUT/fit/report.md (plots: gap.png, replay.png, effect1.png, effect2.png)"
exit $failed
