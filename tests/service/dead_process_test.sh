#!/usr/bin/env bash
# A process that dies: kill -9 the controller, then (in a new run) the plant, then the
# trajectory, mid-run. The others must time out with an error naming the dead role and the step,
# exit non-zero, never hang, and the monitor must write what it recorded, with the step where the
# run stopped.
source "$(dirname "$0")/lib.sh" "$@"
# The jerk-limited move held for 10 s (100,000 steps, about 3 s of lockstep unpaced): a process
# is killed once the monitor has recorded step 20,000 (its progress line in the launcher's
# stderr), mid-run however fast the machine.
scen=$TMP/long.yaml
jerk_move "$scen" 10.0
opts=(--lcm-url "$URL" --step-timeout 2 --linger 1)
for role in controller plant trajectory; do
  out=$TMP/$role
  start=$(date +%s)
  timeout 60 feeddrive-launch "$scen" --out "$out" --no-plots --external "$role" "${opts[@]}" 2> "$TMP/launch-$role.err" & l=$!
  "feeddrive-$role" "$scen" "${opts[@]}" -q & p=$!   # no timeout wrapper: $p must be the process itself
  wait_on_bus $p
  # The fault under test: the process dies at step 20,000 or a little later (the progress line
  # comes every 0.5 s), a point of the run, not of the clock.
  wait_step "$TMP/launch-$role.err" 20000
  kill -9 $p; echo "killed $role"
  set +e; wait $l; rc=$?; set -e
  elapsed=$(( $(date +%s) - start ))
  [ $rc -ne 0 ] || fail "launch exited 0 after the $role died"
  [ $rc -ne 124 ] || fail "launch hung (timeout) after the $role died"
  grep -Eq "from the $role (for|within)? ?.*step [0-9]+|$role.*step [0-9]+" "$TMP/launch-$role.err" ||
    { cat "$TMP/launch-$role.err" >&2; fail "no error naming the $role and the step"; }
  [ -f "$out/summary.json" ] || fail "the monitor wrote no summary ($role killed)"
  [ "$(json "$out/summary.json" .lockstep.completed)" = false ] || fail "summary says completed ($role killed)"
  stopped=$(json "$out/summary.json" .lockstep.stopped_at_step)
  rows=$(( $(wc -l < "$out/timeseries.csv") - 1 ))
  [ "$rows" = "$stopped" ] || fail "$rows rows but stopped_at_step $stopped ($role killed)"
  [ "$stopped" -gt 0 ] && [ "$stopped" -lt 100000 ] || fail "stopped_at_step $stopped ($role killed)"
  failure=$(json "$out/summary.json" .lockstep.failure)
  printf "%s" "$failure" | grep -q "$role" || fail "failure does not name the $role: $failure"
  pass "$role killed: launch exit $rc after ${elapsed}s; stopped at step $stopped: $failure"
done
