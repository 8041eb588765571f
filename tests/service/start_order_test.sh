#!/usr/bin/env bash
# Start order does not matter: start the processes one by one, in reverse dependency order,
# each once the one before has joined the bus; the run completes identical to feeddrive-sim.
source "$(dirname "$0")/lib.sh" "$@"
scen=$SRC/tests/service/scenarios/short_jerk.yaml
sim_run "$scen" "$TMP/sim"
common=(--lcm-url "$URL" --prefix ORDER -q)
# Each one on the bus before the next starts: the order is kept on a loaded machine too.
timeout 120 feeddrive-controller "$scen" "${common[@]}" & c=$!
wait_on_bus $c
timeout 120 feeddrive-monitor "$scen" --out "$TMP/mp" --no-plots "${common[@]}" & m=$!
wait_on_bus $m
timeout 120 feeddrive-plant "$scen" "${common[@]}" & p=$!
wait_on_bus $p
timeout 120 feeddrive-trajectory "$scen" "${common[@]}" & t=$!
for pid in $c $m $p $t; do wait $pid || fail "a process exited $?"; done
same_csv "$TMP/sim/timeseries.csv" "$TMP/mp/timeseries.csv"
pass "controller, monitor, plant, trajectory started in that order: identical"
