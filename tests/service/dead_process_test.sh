#!/usr/bin/env bash
# A process that dies: kill -9 the controller mid-run. The others must time out with an error
# naming the controller and the step, exit non-zero, never hang, and the monitor must write
# what it recorded, with the step where the run stopped.
source "$(dirname "$0")/lib.sh" "$@"
scen=$SRC/scenarios/paper/smc_bl_jerk_limited.yaml
opts=(--lcm-url "$URL" --step-timeout 2 --linger 1)
start=$(date +%s)
timeout 60 feeddrive-launch "$scen" --out "$TMP/mp" --no-plots --external controller "${opts[@]}" 2> "$TMP/launch.err" & l=$!
feeddrive-controller "$scen" "${opts[@]}" -q & c=$!   # no timeout wrapper: $c must be the controller itself
sleep 1.5
kill -9 $c; echo "killed controller"
set +e; wait $l; rc=$?; set -e
elapsed=$(( $(date +%s) - start ))
[ $rc -ne 0 ] || fail "launch exited 0 after the controller died"
[ $rc -ne 124 ] || fail "launch hung (timeout)"
grep -q "no command from the controller for step" "$TMP/launch.err" || { cat "$TMP/launch.err" >&2; fail "no error naming the controller"; }
[ -f "$TMP/mp/summary.json" ] || fail "the monitor wrote no summary"
[ "$(json "$TMP/mp/summary.json" .lockstep.completed)" = false ] || fail "summary says completed"
stopped=$(json "$TMP/mp/summary.json" .lockstep.stopped_at_step)
rows=$(( $(wc -l < "$TMP/mp/timeseries.csv") - 1 ))
[ "$rows" = "$stopped" ] || fail "$rows rows but stopped_at_step $stopped"
[ "$stopped" -gt 0 ] && [ "$stopped" -lt 15000 ] || fail "stopped_at_step $stopped"
failure=$(json "$TMP/mp/summary.json" .lockstep.failure); printf "%s" "$failure" | grep -q controller || fail "failure does not name the controller: $failure"
pass "controller killed: launch exit $rc after ${elapsed}s; stopped at step $stopped: $(json "$TMP/mp/summary.json" .lockstep.failure)"
