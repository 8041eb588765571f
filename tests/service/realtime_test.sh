#!/usr/bin/env bash
# Real-time mode: the plant is paced by the wall clock (1 kHz here) and applies the latest
# command; commands that miss their period are counted. The same controller binary runs
# unchanged. Then a controller that stops answering after 100 steps: after --max-bad-commands
# missed commands in a row the plant goes to the safe state (zero thrust) and says so.
source "$(dirname "$0")/lib.sh" "$@"
scen=$SRC/tests/service/scenarios/realtime_1khz.yaml
start=$(date +%s%N)
timeout 60 feeddrive-launch "$scen" --out "$TMP/rt" --no-plots -q --realtime --lcm-url "$URL"
wall=$(awk -v a="$start" -v b="$(date +%s%N)" 'BEGIN { printf "%.3f", (b - a) / 1e9 }')
rows=$(( $(wc -l < "$TMP/rt/timeseries.csv") - 1 ))
[ "$rows" = 500 ] || fail "$rows rows, expected 500"
[ "$(json "$TMP/rt/summary.json" .lockstep.mode)" = realtime ] || fail "mode is not realtime"
misses=$(json "$TMP/rt/summary.json" .lockstep.deadline_misses)
# Paced by the clock: 0.5 s of simulated time cannot take less than 0.5 s of wall time.
awk -v w="$wall" 'BEGIN { exit !(w >= 0.5) }' || fail "ran in ${wall}s: not paced"
# On a shared 2-core machine a few periods are missed (0 to 5 of 500 measured, also next to a
# CPU hog); a start in which the controller lacks the first 256 steps of references (the bug
# this bound caught) misses about 256. 50 leaves room for load and fails on that.
[ "$misses" -lt 50 ] || fail "$misses of 500 deadlines missed"
pass "real time at 1 kHz: 500 steps in ${wall}s, $misses deadline misses"

timeout 60 feeddrive-launch "$scen" --out "$TMP/safe" --no-plots --realtime --external controller \
  --max-bad-commands 5 --lcm-url "$URL" 2> "$TMP/safe.err" & l=$!
timeout 60 "$BUILD/tests/fd-test-peer" stall-controller --steps 100 --lcm-url "$URL" > /dev/null & c=$!
wait $l || true
wait $c || true
grep -q "safe state, zero thrust" "$TMP/safe.err" || { cat "$TMP/safe.err" >&2; fail "the plant did not announce the safe state"; }
[ "$(json "$TMP/safe/summary.json" .lockstep.safe_state)" = true ] || fail "summary: safe_state is not true"
# After the safe state is entered, every applied u is 0.
last_u=$(tail -n 1 "$TMP/safe/timeseries.csv" | cut -d, -f13)
[ "$last_u" = 0 ] || fail "last applied u = $last_u, expected 0"
pass "controller silent after 100 steps: safe state, zero thrust; $(json "$TMP/safe/summary.json" .lockstep.deadline_misses) missed"
