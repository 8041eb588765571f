#!/usr/bin/env bash
# Hardware in the loop: the example drive adapter (examples/c/drive_adapter.c, a drive model of its
# own: mass, viscous friction and a smooth Stribeck curve, a 0.1 um encoder, RK4; configured from
# run_info_t)
# takes the plant's role (--external plant), as docs/external-plant.md describes:
#   1. lockstep at 10 kHz (robust_smc: observers, no true state needed)
#   2. real time at 1 kHz (hil_1khz)
#   3. a keyed run (--key), the adapter signing with examples/c/fd_sign.h
#   4. with an external controller too (the C sketch of docs/external-controllers.md)
# and the protocol errors of docs/external-plant.md, each failing fast with one line naming it:
#   5. an unsigned adapter in a keyed run (within 2 s, naming the plant and the key)
#   6. an adapter that skips a step number (the controller names the plant)
#   7. a restarted adapter (within 1 s of its return: "the plant restarted")
source "$(dirname "$0")/lib.sh" "$@"
command -v cc > /dev/null || skip "no C compiler"
mkdir -p "$TMP/gen"
lcm-gen -c --c-cpath "$TMP/gen" --c-hpath "$TMP/gen" "$SRC"/lcmtypes/*.lcm
cc -O2 -Wall -Wextra -Werror -Wno-unused-parameter -I"$SRC/examples/c" -I"$TMP/gen" "$SRC/examples/c/drive_adapter.c" \
  "$TMP"/gen/*.c -llcm -lcrypto -lm -o "$TMP/adapter" || fail "the example drive adapter does not compile"
awk '/^## 7\. A C sketch/ { s = 1 } s && /^```c$/ { c = 1; next } c && /^```$/ { exit } c' \
  "$SRC/docs/external-controllers.md" > "$TMP/controller.c"
cc -O2 -Wall -Wextra -Werror -Wno-unused-parameter -I"$TMP/gen" "$TMP/controller.c" "$TMP"/gen/*.c -llcm -lm \
  -o "$TMP/controller" || fail "the C sketch does not compile"
hil=$SRC/scenarios/robustness/robust_smc.yaml
khz=$SRC/tests/service/scenarios/hil_1khz.yaml
head -c 32 /dev/urandom > "$TMP/run.key"; chmod 600 "$TMP/run.key"

# run NAME SCENARIO [launcher options...]: the adapter first (it announces the run id), then the
# launcher; both must succeed. The adapter's stderr is in $TMP/NAME.adapter.
run() {
  local name=$1 scen=$2; shift 2
  timeout 120 "$TMP/adapter" --url "$URL" ${ADAPTER_ARGS:-} 2> "$TMP/$name.adapter" & local a=$!
  timeout 300 feeddrive-launch "$scen" --out "$TMP/$name" --no-plots -q --lcm-url "$URL" --external plant "$@" \
    || { cat "$TMP/$name.adapter" >&2; fail "$name: the run failed"; }
  wait $a || { cat "$TMP/$name.adapter" >&2; fail "$name: the adapter failed"; }
  [ "$(json "$TMP/$name/summary.json" .lockstep.completed)" = true ] || fail "$name: not completed"
  # No true state from hardware: the true-state metrics are null, the measured ones are there.
  [ "$(json "$TMP/$name/summary.json" .position_error_max_abs_m)" = null ] || fail "$name: a true-state error without truth"
  [ "$(json "$TMP/$name/summary.json" .error_source)" = measured ] || fail "$name: error_source not measured"
}
# The adapter configured itself from run_info_t (nothing given by hand): its line has the run's values.
configured() {
  grep -q "$2 (.*): T = $3 s, $4 steps, m = 102.04 kg, Ka\*Kf = 260 N/V, b = 0.4 N\*s/m, Fc = 80 N, Fs = 120 N, vs = 0.1 m/s, delta = 2, q = 1e-07 m, x0 = 0 m, scenario sha256 $(sha256sum "$5" | cut -c1-12)" \
    "$TMP/$1.adapter" || { cat "$TMP/$1.adapter" >&2; fail "$1: the adapter did not configure itself from run_info_t"; }
}
em() { json "$TMP/$1/summary.json" .measured_position_error_max_abs_m; }

# 1. Lockstep, 10 kHz. The bound: the encoder's 0.1 um quantisation and the adapter's Stribeck
# curve (which the law's observers model differently) feed back (measured 0.43 um max
# |xd - x_measured|; 0.30 um with Coulomb friction alone); 2 um leaves room (commands that did not act over the 100 mm move
# would leave millimetres).
run lockstep "$hil"
configured lockstep robust_smc 0.0001 15000 "$hil"
awk -v e="$(em lockstep)" 'BEGIN { exit !(e > 0 && e < 2e-6) }' || fail "lockstep: measured max |e| = $(em lockstep) m"
pass "lockstep with the drive adapter: completed, measured max |e| = $(em lockstep) m, configured from run_info_t"

# 2. Real time at 1 kHz against lockstep at 1 kHz. The adapter (a model) applies command k over
# step k when it came before the deadline, as lockstep does: measured 11.8 um in both (the 1 kHz
# loop with lambda = 50, 11-34 deadline misses in the real-time runs). A missed deadline holds the
# previous command one period more; 1.5x the lockstep figure leaves room for a few, a drive that
# ignored the commands would be off by millimetres.
run khz_lockstep "$khz"
run realtime "$khz" --realtime
configured realtime hil_1khz 0.001 1000 "$khz"
[ "$(json "$TMP/realtime/summary.json" .lockstep.mode)" = realtime ] || fail "realtime: not a real-time run"
# Without a missed deadline the real-time run applies the same commands as lockstep: the same
# error within 1.5x (the drive's own encoder noise is seeded per run). A missed deadline holds the
# last command for a period (the machine took the CPU: a shared VM), which can multiply the error;
# then the run must still complete with fewer than 5 % of its periods missed.
misses=$(json "$TMP/realtime/summary.json" .lockstep.deadline_misses)
steps=$(json "$TMP/realtime/summary.json" .lockstep.steps_expected)
if [ "$misses" = 0 ]; then
  awk -v e="$(em realtime)" -v l="$(em khz_lockstep)" 'BEGIN { exit !(e < 1.5 * l) }' ||
    fail "realtime: measured max |e| $(em realtime) m against lockstep $(em khz_lockstep) m, no deadline missed"
else
  [ $((misses * 20)) -lt "$steps" ] || fail "realtime: $misses of $steps deadlines missed"
fi
pass "real time at 1 kHz: completed, measured max |e| $(em realtime) m (lockstep $(em khz_lockstep) m), $(json "$TMP/realtime/summary.json" .lockstep.deadline_misses) deadline misses"

# 3. A keyed run: every message signed, none rejected.
ADAPTER_ARGS="--key $TMP/run.key" run keyed "$hil" --key "$TMP/run.key"
[ "$(json "$TMP/keyed/summary.json" .lockstep.authenticated)" = true ] || fail "keyed: not authenticated"
[ "$(json "$TMP/keyed/summary.json" .lockstep.unauthenticated_messages)" = 0 ] || fail "keyed: messages rejected"
awk -v e="$(em keyed)" 'BEGIN { exit !(e > 0 && e < 2e-6) }' || fail "keyed: measured max |e| = $(em keyed) m"
pass "--key: completed, authenticated, measured max |e| = $(em keyed) m"

# 4. An external controller too: the C sketch of the docs (configured from run_info_t as well).
# The sketch's law without its integral on this drive's friction (viscous and smooth Coulomb, which
# its Coulomb feedforward models): measured 0.87 um; 5 um leaves room (the reference moves 100 mm:
# commands that did not act would leave errors of millimetres).
timeout 120 "$TMP/controller" "$URL" FD 2> "$TMP/ext.controller" & c=$!
run ext "$SRC/scenarios/paper/smc_bl_jerk_limited.yaml" --external controller
wait $c || { cat "$TMP/ext.controller" >&2; fail "ext: the C controller failed"; }
awk -v e="$(em ext)" 'BEGIN { exit !(e > 0 && e < 5e-6) }' || fail "ext: measured max |e| = $(em ext) m"
pass "external plant and external controller: completed, measured max |e| = $(em ext) m"

# 5. An unsigned adapter in a keyed run: the monitor names the plant and the key, the run fails
# within 2 s (the launcher then stops the processes that never joined: 1 s more).
timeout 60 "$TMP/adapter" --url "$URL" 2> /dev/null & a=$!
start=$(date +%s.%N)
set +e
timeout 60 feeddrive-launch "$hil" --out "$TMP/unsigned" --no-plots -q --lcm-url "$URL" --external plant \
  --key "$TMP/run.key" 2> "$TMP/unsigned.err"; rc=$?
set -e
took=$(echo "$(date +%s.%N) - $start" | bc)
kill $a 2>/dev/null || true
[ $rc = 1 ] || { cat "$TMP/unsigned.err"; fail "unsigned: exit $rc"; }
[ "$(grep -c "the plant publishes unsigned messages on FD_STATUS, but this run is authenticated with --key $TMP/run.key" "$TMP/unsigned.err")" = 1 ] ||
  { cat "$TMP/unsigned.err"; fail "unsigned: no single line naming the plant and the key"; }
awk -v t="$took" 'BEGIN { exit !(t < 4) }' || fail "unsigned: took $took s"
pass "unsigned adapter in a keyed run: exit 1 after $took s: $(grep -m1 unsigned "$TMP/unsigned.err" | cut -c1-160)..."

# 6. A skipped step number: state 501 in place of 500. The controller names the plant.
timeout 60 "$TMP/adapter" --url "$URL" --skip-at 500 2> /dev/null & a=$!
set +e
timeout 60 feeddrive-launch "$hil" --out "$TMP/skip" --no-plots -q --lcm-url "$URL" --external plant 2> "$TMP/skip.err"; rc=$?
set -e
kill $a 2>/dev/null || true
[ $rc = 1 ] || { cat "$TMP/skip.err"; fail "skip: exit $rc"; }
grep -q "protocol error of the plant: it published state 501 while step 500 has no command yet" "$TMP/skip.err" ||
  { cat "$TMP/skip.err"; fail "skip: the plant is not named"; }
# The record reaches the last complete step before the failure: 0..498 (step 499's row needs
# state 500, which carries what was applied during 499, and state 500 never came).
[ "$(json "$TMP/skip/summary.json" .steps)" = 499 ] || fail "skip: $(json "$TMP/skip/summary.json" .steps) steps recorded, expected 499"
pass "skipped step: exit 1, the plant named, 499 steps recorded"

# 7. A restarted drive: the adapter dies at step 3000 and a new one starts (a new run id). The
# monitor says the plant restarted within 1 s of the new one's first heartbeat (2.5 s with the
# adapter's start and the launcher's exit).
# restart NAME WHAT [ADAPTER/LAUNCH OPTIONS...]: the adapter dies at step 3000, a new one starts
# 0.5 s later; the run fails with exit 1 and one line saying the plant restarted, within 2.5 s.
restart() {
  local name=$1 what=$2 a a2 l rc start took
  shift 2
  timeout 60 "$TMP/adapter" --url "$URL" "$@" --exit-at 3000 2> /dev/null & a=$!
  timeout 60 feeddrive-launch "$hil" --out "$TMP/$name" --no-plots -q --lcm-url "$URL" --external plant "$@" 2> "$TMP/$name.err" & l=$!
  wait $a || true
  sleep 0.5  # under test: the new adapter comes 0.5 s after the old one died (deliberate, not a wait)
  start=$(date +%s.%N)
  timeout 60 "$TMP/adapter" --url "$URL" "$@" 2> /dev/null & a2=$!
  set +e
  wait $l; rc=$?
  set -e
  took=$(echo "$(date +%s.%N) - $start" | bc)
  kill $a2 2>/dev/null || true
  [ $rc = 1 ] || { cat "$TMP/$name.err"; fail "$what: exit $rc"; }
  [ "$(grep -c "monitor: the plant restarted" "$TMP/$name.err")" = 1 ] ||
    { cat "$TMP/$name.err"; fail "$what: no single line saying the plant restarted"; }
  awk -v t="$took" 'BEGIN { exit !(t < 2.5) }' || { cat "$TMP/$name.err"; fail "$what: took $took s"; }
  pass "$what: exit 1 after $took s: $(grep -m1 "the plant restarted" "$TMP/$name.err" | cut -c1-160)..."
}
restart restart "restarted adapter"

# 7b. The same, with one run id given to both (docs/deployment.md's fixed --run-id, no key):
# the new adapter's heartbeat goes back ("starting" at step -1 after "running"): a restart,
# named as such within the same bound, although the new adapter would resume at the run's
# current step (a record joining two drives' motions must not pass as complete). With --key a
# heartbeat that goes back is a replay, ignored: service.bus_attack_test case 8.
restart restart_same "restarted adapter, same run id" --run-id 777
