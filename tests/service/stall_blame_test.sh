#!/usr/bin/env bash
# Errors name the right culprit.
# 1. The controller stalls (SIGSTOP) past the step timeout, then resumes (SIGCONT): the plant
#    names the controller, and so must every other process (trajectory, monitor, and the
#    controller itself, which finds the plant's failure when it wakes), never "no state from the
#    plant" (the race the trajectory's and the controller's own timeouts used to win).
# 1b. The controller killed (SIGKILL): the run's failure names it, never the plant.
# 2. A controller that answers with a stale step number (state k answered as k - 1, with a new
#    u) gets a counted error naming the stale step at once, not a silent drop and a timeout: a
#    second, different command for a step already answered is a conflict (service::Node::admit),
#    which names the channel and the step and says it may be a stale step number.
source "$(dirname "$0")/lib.sh" "$@"
scen=$TMP/long.yaml
jerk_move "$scen" 10.0
opts=(--lcm-url "$URL" --step-timeout 2 --linger 1)
timeout 60 feeddrive-launch "$scen" --out "$TMP/stall" --no-plots --external controller "${opts[@]}" 2> "$TMP/launch.err" & l=$!
feeddrive-controller "$scen" "${opts[@]}" 2> "$TMP/controller.err" & c=$!
wait_on_bus $c
wait_step "$TMP/launch.err" 20000  # the fault under test: stopped mid-run, at step 20,000 (of 100,000)
kill -STOP $c; echo "controller stopped"
# Resumed once the plant has failed (its 2 s step timeout): its error line is in the launcher's
# stderr.
wait_until 30 "the plant failed while the controller was stopped" grep -q "feeddrive-plant\] \[error\]" "$TMP/launch.err"
kill -CONT $c; echo "controller resumed"
set +e; wait $l; rl=$?; wait $c; rc=$?; set -e
[ $rl -ne 0 ] && [ $rl -ne 124 ] || fail "launch exit $rl"
[ $rc -ne 0 ] || fail "the controller exited 0 after the plant failed"
# Each process's error line (the monitor's is its closing line: "N steps recorded (stopped at
# step k: why)").
cat "$TMP/launch.err" "$TMP/controller.err" | grep -E "\[error\]|stopped at step" > "$TMP/errors" || true
for role in plant trajectory monitor controller; do
  grep "feeddrive-$role\]" "$TMP/errors" > "$TMP/$role.lines" || fail "no error line from the $role: $(cat "$TMP/errors")"
  grep -v "still running" "$TMP/$role.lines" | grep -qv "controller" && { cat "$TMP/$role.lines" >&2; fail "the $role blames someone else"; }
  echo "$role: $(head -n 1 "$TMP/$role.lines")"
done
grep -q "no state from the plant" "$TMP/errors" && fail "a process blamed the plant"
json "$TMP/stall/summary.json" .lockstep.failure | grep -q "controller" || fail "summary failure does not name the controller"
pass "stalled controller: every process names it"

# 1b. The controller killed (SIGKILL): the monitor, whose own step timeout runs alongside the
# plant's, must not name the plant (it once wrote "no command k from the controller, state k+1
# from the plant" in 1 of 3 runs): the plant's heartbeat still comes, so it waits for the plant,
# which names the controller.
timeout 60 feeddrive-launch "$scen" --out "$TMP/kill" --no-plots --external controller "${opts[@]}" 2> "$TMP/kill.err" & l=$!
feeddrive-controller "$scen" "${opts[@]}" 2> /dev/null & c=$!
wait_on_bus $c
wait_step "$TMP/kill.err" 20000  # the fault under test: killed mid-run, at step 20,000 (of 100,000)
kill -KILL $c
set +e; wait $l; rl=$?; wait $c; set -e
[ $rl -ne 0 ] || fail "launch exited 0 with its controller killed"
failure=$(json "$TMP/kill/summary.json" .lockstep.failure)
printf "%s" "$failure" | grep -q "controller" || fail "killed controller: the failure does not name it: $failure"
printf "%s" "$failure" | grep -q "from the plant" && fail "killed controller: the monitor blames the plant too: $failure"
pass "killed controller: $failure"

timeout 60 feeddrive-launch "$scen" --out "$TMP/stale" --no-plots --external controller "${opts[@]}" 2> "$TMP/stale.err" & l=$!
timeout 60 "$BUILD/tests/fd-test-peer" stale-controller --steps 100 --lcm-url "$URL" > /dev/null & p=$!
set +e; wait $l; rl=$?; wait $p; set -e
[ $rl -ne 0 ] || fail "launch exited 0 with a stale controller"
grep -q "\[feeddrive-plant\] \[error\] conflict on FD_CMD step 99: two different control_command_t .*stale step number" "$TMP/stale.err" ||
  { cat "$TMP/stale.err" >&2; fail "no error naming the stale step"; }
failure=$(json "$TMP/stale/summary.json" .lockstep.failure)
printf "%s" "$failure" | grep -q "step 99.*stale step number" || fail "the failure does not name the stale step: $failure"
[ "$(json "$TMP/stale/summary.json" .lockstep.stopped_at_step)" -le 101 ] || fail "not stopped at once"
pass "stale step number: named at once: $failure"
