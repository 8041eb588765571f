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
# The recording options hold for the monitor too (one writer, sim::RunWriter): every 7th row, three
# columns, the same bytes as feeddrive-sim, and the summary still of every step.
scen=$TMP/options.yaml
jerk_move "$scen" 0.3
printf 'output: {every: 7, columns: [t, x, u]}\n' >> "$scen"
sim_run "$scen" "$TMP/sim_options"
timeout 300 feeddrive-launch "$scen" --out "$TMP/mp_options" --no-plots -q --lcm-url "$URL"
same_csv "$TMP/sim_options/timeseries.csv" "$TMP/mp_options/timeseries.csv"
[ "$(head -n 1 "$TMP/mp_options/timeseries.csv")" = "t,x,u" ] || fail "options: header $(head -n 1 "$TMP/mp_options/timeseries.csv")"
rows=$(( $(wc -l < "$TMP/mp_options/timeseries.csv") - 1 ))
[ "$rows" = $(( (3000 + 6) / 7 )) ] || fail "options: $rows rows"
[ "$(json "$TMP/mp_options/summary.json" .steps)" = 3000 ] || fail "options: summary not of every step"
[ "$(json "$TMP/mp_options/summary.json" .position_error_p95_abs_m)" = "$(json "$TMP/sim_options/summary.json" .position_error_p95_abs_m)" ] ||
  fail "options: p95 differs"
pass "output.every 7 and output.columns [t, x, u]: $rows rows identical to feeddrive-sim, summary of all 3000 steps"
