#!/usr/bin/env bash
# Commands a drive must never apply: an external controller sends NaN at k % 7 == 3 and 1e9 V at
# k % 7 == 5. The plant rejects NaN (applies 0 V), clips 1e9 to its input limit (100 V), counts
# both, and the run completes. Also: junk on every channel (a reference_t on the command
# channel, a command on the state channel, random bytes on the reference channel) is counted
# and ignored, and a clean run with junk flying around stays identical to feeddrive-sim.
source "$(dirname "$0")/lib.sh" "$@"
scen=$SRC/tests/service/scenarios/short_jerk.yaml
steps=1000
timeout 120 feeddrive-launch "$scen" --out "$TMP/nan" --no-plots -q --external controller --lcm-url "$URL" & l=$!
timeout 120 "$BUILD/tests/fd-test-peer" nan-controller --lcm-url "$URL" > /dev/null & c=$!
wait $l || fail "launch failed with the NaN controller"
wait $c || true
expected=$(( 2 * (steps / 7) + ( (steps % 7) > 3 ? 1 : 0 ) + ( (steps % 7) > 5 ? 1 : 0 ) ))
got=$(json "$TMP/nan/summary.json" .lockstep.rejected_commands)
[ "$got" = "$expected" ] || fail "rejected_commands $got, expected $expected"
# Row k = 3 (NaN): u = 0 applied; row k = 5 (1e9 V): u = 100 V applied.
u3=$(awk -F, 'NR == 5 { print $13 }' "$TMP/nan/timeseries.csv")
u5=$(awk -F, 'NR == 7 { print $13 }' "$TMP/nan/timeseries.csv")
[ "$u3" = 0 ] || fail "step 3: applied u = $u3, expected 0"
[ "$u5" = 100 ] || fail "step 5: applied u = $u5, expected 100"
pass "NaN rejected and 1e9 V clipped: $got commands counted"

sim_run "$scen" "$TMP/sim"
timeout 60 "$BUILD/tests/fd-test-peer" junk --seconds 4 --lcm-url "$URL" > /dev/null & j=$!
wait_on_bus $j
timeout 120 feeddrive-launch "$scen" --out "$TMP/junk" --no-plots -q --lcm-url "$URL"
wait $j
same_csv "$TMP/sim/timeseries.csv" "$TMP/junk/timeseries.csv"
invalid=$(json "$TMP/junk/summary.json" .lockstep.invalid_messages)
[ "$invalid" -gt 0 ] || fail "no invalid messages counted"
pass "junk on every channel: $invalid invalid messages counted and ignored; identical"
