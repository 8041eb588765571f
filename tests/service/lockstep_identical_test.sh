#!/usr/bin/env bash
# Determinism: a four-process lockstep run writes a timeseries.csv identical, byte for byte, to
# feeddrive-sim's, on the paper's jerk-limited move (hard sgn, 20 us, 75,000 steps) and on the
# ramp with friction, ripple and grinding (50,000 steps; this one with every process pinned to
# one CPU, feeddrive-launch --cpus, which changes timing and nothing else).
source "$(dirname "$0")/lib.sh" "$@"
for s in smc_jerk_limited smc_ramp_all_forces; do
  scen=$SRC/scenarios/paper/$s.yaml
  sim_run "$scen" "$TMP/sim_$s"
  pin=()
  [ "$s" = smc_ramp_all_forces ] && pin=(--cpus "$(taskset -pc $$ | sed 's/.*: *//; s/[-,].*//')")
  timeout 600 feeddrive-launch "$scen" --out "$TMP/mp_$s" --no-plots -q --lcm-url "$URL" "${pin[@]}"
  same_csv "$TMP/sim_$s/timeseries.csv" "$TMP/mp_$s/timeseries.csv"
  [ "$(json "$TMP/mp_$s/summary.json" .lockstep.completed)" = true ] || fail "$s: not completed"
  steps=$(json "$TMP/mp_$s/summary.json" .steps)
  [ "$steps" = "$(json "$TMP/sim_$s/summary.json" .steps)" ] || fail "$s: $steps steps"
  pass "$s: $steps steps identical to feeddrive-sim; state->command p50 $(json "$TMP/mp_$s/summary.json" .lockstep.latency_us.state_to_command.p50) us"
done
