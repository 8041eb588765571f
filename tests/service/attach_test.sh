#!/usr/bin/env bash
# The monitor attaches to a running system: a second feeddrive-monitor --attach joins a lockstep
# run mid-way. It records from the first state it sees to the end, and every row it writes is
# identical to the same step's row of the run's own monitor. It asks for what it missed (a
# datagram its socket dropped under load: CI once lost one, and the attached monitor's failure
# then stopped the whole run), so no step is missing; its failure could not stop the run any
# more either (tests/integrity NodePeers).
source "$(dirname "$0")/lib.sh" "$@"
# 10 s of the jerk-limited move (100,000 steps, about 3 s of lockstep at 33,000 steps/s): long
# enough to join at step 25,000 and be stopped while the run goes on 25,000 steps (points of the
# run, read from the run's monitor's progress line in launch.err, not of the clock: so on a
# machine of any speed it joins mid-run and misses more than its socket holds).
scen=$TMP/long.yaml
jerk_move "$scen" 10.0
timeout 120 feeddrive-launch "$scen" --out "$TMP/run" --no-plots --lcm-url "$URL" 2> "$TMP/launch.err" & l=$!
wait_on_bus $l feeddrive-monitor
wait_step "$TMP/launch.err" 25000  # under test: joining a run mid-way
timeout 120 feeddrive-monitor "$scen" --attach --out "$TMP/attached" --no-plots --lcm-url "$URL" --step-timeout 5 2> "$TMP/attached.err" & m=$!
# Then it loses the CPU while the run goes on 25,000 steps (SIGSTOP: what a loaded machine does to it):
# its 4 MB socket buffer holds about 0.1 s of the run, the rest is dropped by the kernel, and
# it must get every step back by asking (the publishers keep the last 65,536 steps and linger
# after the end while it still records).
wait_on_bus $m
mon=$(pgrep -P $m) || fail "no feeddrive-monitor --attach under timeout $m"
kill -STOP "$mon" # the pause under test: until the run has gone on 25,000 steps (0.75 s at 33,000 steps/s)
wait_step "$TMP/launch.err" $(($(monitor_step "$TMP/launch.err") + 25000))
kill -CONT "$mon"
wait $l || { tail -c 2000 "$TMP/launch.err" >&2; fail "the run failed"; }
wait $m || { tail -5 "$TMP/attached.err" >&2; fail "the attached monitor failed"; }
total=$(( $(wc -l < "$TMP/run/timeseries.csv") - 1 ))
rows=$(( $(wc -l < "$TMP/attached/timeseries.csv") - 1 ))
[ "$total" = 100000 ] || fail "the run recorded $total rows, expected 100000"
[ "$rows" -gt 0 ] && [ "$rows" -lt "$total" ] || fail "the attached monitor recorded $rows rows (joined mid-way: 0 < rows < $total)"
missing=$(json "$TMP/attached/summary.json" .lockstep.missing_steps)
asked=$(json "$TMP/attached/summary.json" .lockstep.lost)
[ "$asked" -gt 0 ] || fail "the attached monitor, stopped for 25,000 steps, asked for nothing again: did its socket not overflow?"
[ "$missing" = 0 ] || fail "the attached monitor skipped $missing steps: $(jq -c .lockstep.gaps "$TMP/attached/summary.json")"
# The attached rows are the last $rows rows of the run, byte for byte (same header too).
same_csv <(head -n 1 "$TMP/run/timeseries.csv"; tail -n "$rows" "$TMP/run/timeseries.csv") "$TMP/attached/timeseries.csv"
pass "attached mid-run: recorded the last $rows of $total steps (stopped for 25,000 steps; $asked messages asked for again), identical to the run's monitor"
