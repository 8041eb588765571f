#!/usr/bin/env bash
# Attacks on the bus (issue 13; docs/security.md), each against a real lockstep run in this
# test's private network namespace, with the run checked against feeddrive-sim byte for byte:
#   1. forged commands: a peer answers every state k at once with its own command for step k
#      (u = 3 V). Without a key: a conflict, the run fails with one line naming channel, step
#      and fields. With --key: the forgeries are rejected as unauthenticated, the run completes
#      identical to feeddrive-sim.
#   2. forged reference blocks (position 1.0 m, 512 steps ahead of the trajectory): the same.
#   3. a replayed log (stock lcm-logplayer of an earlier run, started mid-run): its messages are
#      foreign (another run id), counted and ignored; the run completes identical, and
#      summary.json says how many. With --key, the replay of a signed run is foreign too.
#   3b. with --key and the same --run-id reused (docs/deployment.md's fixed run id across
#      machines), a replayed signed log is foreign too: the plant binds the run id to a fresh
#      nonce (docs/security.md, "Replays across runs").
#   5. the malformed datagrams that once killed every process (issue 19: a status whose role has
#      length 0, reference blocks with count -1 and 10^7, a command and a state with mac_size -1),
#      sent every 5 ms through a whole run: counted invalid per channel, the run identical.
#   6. a forged monitor heartbeat saying "running" every 10 ms: it does not hold the others open
#      after the real monitor is done (with --linger 60, the launch ends long before 60 s).
#   7. forged heartbeats (issue 19's review): the monitor acknowledging step 10^9, the plant at
#      step 10^9, an attached monitor "running" that seems to progress; no key, --linger 60: the
#      run completes identical, nothing says "restarted", the launch ends in seconds. (Without a
#      key a plant heartbeat that goes back is a restart and fails the run: hil_test case 7b.)
#   8. with --key, the run's own signed heartbeats of its first 0.3 s replayed through the rest
#      of it (the plant's go back): the run completes identical.
#   9. with --key, the same unsigned forgeries (case 7's heartbeats, and junk on the command
#      and state channels from before the start): counted unauthenticated, never a reason to end
#      the run, since each role is filled by its own process (issue 19's review: three unsigned
#      "monitor" heartbeats ended a keyed run).
#   4. concurrent runs with the default settings: the second launch refuses at once, in one
#      line, naming the run that holds the group and how to choose another (exit 2); with
#      another --prefix both complete identical. Two launches started at the same instant
#      (both past the check): each ignores the other's messages as foreign; both complete.
source "$(dirname "$0")/lib.sh" "$@"
scen=$SRC/scenarios/paper/smc_bl_ramp_all_forces.yaml
sim_run "$scen" "$TMP/sim"
KEY=$TMP/key
head -c 32 /dev/urandom > "$KEY"
chmod 600 "$KEY"

# launch NAME ARGS...: feeddrive-launch into $TMP/NAME, log in $TMP/NAME.log; sets rc.
launch() {
  local name=$1
  shift
  rc=0
  timeout 300 feeddrive-launch "$scen" --out "$TMP/$name" --no-plots -q --lcm-url "$URL" "$@" > "$TMP/$name.log" 2>&1 || rc=$?
}
# peer MODE: an attacker (tests/service/tools/test_peer.cpp) on the bus, before the run starts.
peer() {
  timeout 300 "$BUILD/tests/fd-test-peer" "$1" --lcm-url "$URL" > "$TMP/peer.log" 2>&1 & peer_pid=$!
  wait_on_bus $peer_pid
}
# child_of PID NAME: prints the pid of PID's child running NAME, waiting up to 10 s for it.
child_of() {
  wait_until 10 "a $2 under process $1" pgrep -P "$1" -f "$2" > /dev/null
  pgrep -P "$1" -f "$2" | head -n 1
}
# plant_up PID: waits until the feeddrive-launch under PID (a `launch ... &` subshell or a
# `timeout feeddrive-launch &`) has started its plant: it passed the group check.
plant_up() {
  local p=$1 t
  t=$(pgrep -P "$p" -x timeout | head -n 1 || true)
  [ -n "$t" ] && p=$t
  child_of "$(child_of "$p" feeddrive-launch)" feeddrive-plant > /dev/null
}
# conflict_failure NAME CHANNEL: the run NAME failed with a one-line conflict error on CHANNEL.
conflict_failure() {
  local name=$1 channel=$2 line
  [ "$rc" = 1 ] || { tail -5 "$TMP/$name.log" >&2; fail "$name: launch exited $rc, expected 1 (a conflict)"; }
  line=$(grep -m1 -o "conflict on $channel step [0-9]*: two different [a-z_]* for one step ([a-z_., ]* differ)[^\"]*" "$TMP/$name.log") ||
    { tail -5 "$TMP/$name.log" >&2; fail "$name: no one-line conflict error on $channel in the log"; }
  [ "$(json "$TMP/$name/summary.json" .lockstep.completed)" = false ] || fail "$name: summary.json says completed"
  json "$TMP/$name/summary.json" .lockstep.failure | grep -q "conflict on $channel step" ||
    fail "$name: summary.json's failure does not name the conflict: $(json "$TMP/$name/summary.json" .lockstep.failure)"
  echo "  $name: $line"
}
# completed_identical NAME: the run completed and its record is feeddrive-sim's.
completed_identical() {
  [ "$rc" = 0 ] || { tail -5 "$TMP/$1.log" >&2; fail "$1: launch exited $rc"; }
  [ "$(json "$TMP/$1/summary.json" .lockstep.completed)" = true ] || fail "$1: not completed"
  [ "$(json "$TMP/$1/summary.json" .lockstep.conflicts)" = 0 ] || fail "$1: conflicts in a completed run"
  same_csv "$TMP/sim/timeseries.csv" "$TMP/$1/timeseries.csv"
}

# completed_identical_despite NAME: the run completed, its record is feeddrive-sim's, and the
# forgeries it ignored were counted as conflicts (a heartbeat that goes back is one).
completed_identical_despite() {
  [ "$rc" = 0 ] || { tail -5 "$TMP/$1.log" >&2; fail "$1: launch exited $rc"; }
  [ "$(json "$TMP/$1/summary.json" .lockstep.completed)" = true ] || fail "$1: not completed"
  same_csv "$TMP/sim/timeseries.csv" "$TMP/$1/timeseries.csv"
}

# A key that group or others can read is refused before anything starts: exit 2, one line.
cp "$KEY" "$TMP/open.key"
chmod 644 "$TMP/open.key"
rc=0
feeddrive-launch "$scen" --out "$TMP/open" --no-plots -q --lcm-url "$URL" --key "$TMP/open.key" > "$TMP/open.log" 2>&1 || rc=$?
[ "$rc" = 2 ] || { cat "$TMP/open.log" >&2; fail "a 0644 key: launch exited $rc, expected 2"; }
[ "$(grep -c "" "$TMP/open.log")" = 1 ] && grep -q "error: --key .*open.key: mode 0644 lets group or others access it; run chmod 600" "$TMP/open.log" ||
  { cat "$TMP/open.log" >&2; fail "a 0644 key: not the one-line error"; }
[ -e "$TMP/open" ] && fail "a 0644 key: an output folder was made"
pass "a 0644 key refused: $(cat "$TMP/open.log")"

# 0. A clean run, recorded by the stock lcm-logger for the replay below.
lcm-logger --lcm-url="$URL" --channel='FD_.*' --force "$LOGDIR/old.lcmlog" > /dev/null 2>&1 & lg=$!
wait_on_bus $lg
launch clean
kill -INT $lg; wait $lg || true
completed_identical clean
for f in foreign_messages conflicts unauthenticated_messages; do
  [ "$(json "$TMP/clean/summary.json" ".lockstep.$f")" = 0 ] || fail "clean: $f = $(json "$TMP/clean/summary.json" ".lockstep.$f")"
done
[ "$(json "$TMP/clean/summary.json" .lockstep.run_id)" -gt 0 ] || fail "clean: no run id in summary.json"
pass "clean run: identical to feeddrive-sim, run id $(json "$TMP/clean/summary.json" .lockstep.run_id), 0 foreign/conflicts/unauthenticated"

# forged WHAT MODE CHANNEL MIN: the attacker MODE against a run without a key (a conflict on
# CHANNEL fails the run) and with --key (at least MIN forgeries rejected; identical run).
forged() {
  local what=$1 mode=$2 channel=$3 min=$4 n
  peer "$mode"
  launch "$mode"
  wait $peer_pid || true
  conflict_failure "$mode" "$channel"
  if [ "$mode" = forge-controller ]; then
    # The race (issue 19, point 10): the summary names the command the plant applied and its
    # sender, and the record keeps that step.
    local step applied sender rows
    step=$(json "$TMP/$mode/summary.json" .lockstep.command_conflict.step)
    applied=$(json "$TMP/$mode/summary.json" .lockstep.command_conflict.applied.u)
    sender=$(json "$TMP/$mode/summary.json" .lockstep.command_conflict.applied.sender)
    if [ "$applied" = null ]; then  # the plant had both before it integrated: it applied neither
      json "$TMP/$mode/summary.json" .lockstep.failure | grep -q "did not come (it stopped on the conflict before applying either" ||
        fail "$mode: neither applied nor said so: $(jq -c .lockstep.command_conflict "$TMP/$mode/summary.json")"
      echo "  step $step: the plant stopped before applying either: $(jq -c .lockstep.command_conflict "$TMP/$mode/summary.json")"
    else
    # Named by the process that owns the source port, or, when that process had exited before
    # the monitor read the command (a loaded monitor reads its backlog late, and the run ends at
    # once on the conflict), by the role whose heartbeats came from the same socket.
    echo "$sender" | grep -Eq "^[0-9.]+:[0-9]+ ([a-z-]+ \(pid [0-9]+\)|\(the [a-z]+'s socket, by its heartbeats; no local process owns it now\))\$" ||
      fail "$mode: no sender of the applied command: $sender"
    json "$TMP/$mode/summary.json" .lockstep.failure | grep -q "the plant applied u = " || fail "$mode: the failure line does not name the applied command"
    rows=$(( $(grep -c "" "$TMP/$mode/timeseries.csv") - 1 ))
    [ "$rows" -gt "$step" ] || fail "$mode: the record ($rows rows) does not keep step $step"
    echo "  applied at step $step: $(jq -c .lockstep.command_conflict.applied "$TMP/$mode/summary.json"); $rows rows recorded"
    fi
  fi
  pass "forged $what without a key: the run failed on the conflict"
  peer "$mode"
  launch "$mode-key" --key "$KEY"
  wait $peer_pid || true
  completed_identical "$mode-key"
  n=$(json "$TMP/$mode-key/summary.json" .lockstep.unauthenticated_messages)
  [ "$n" -ge "$min" ] || fail "$mode-key: only $n unauthenticated messages counted ($(tail -n 1 "$TMP/peer.log"))"
  pass "forged $what with --key: $n rejected as unauthenticated ($(tail -n 1 "$TMP/peer.log")); identical to feeddrive-sim"
}
# 1. Forged commands: one per step, 10000.
forged commands forge-controller FD_CMD 5000
# 2. Forged reference blocks: one per 16 steps up to 512 before the end, 593.
forged "reference blocks" forge-reference FD_REF 300

# 3. A replayed log, started once the new run's plant is up (before, the launch would refuse:
# another run's plant is on the group, case 4).
replay_into() {  # replay_into NAME LOG ARGS...
  local name=$1 log=$2
  shift 2
  launch "$name" "$@" & l=$!
  plant_up $l
  timeout 120 lcm-logplayer --lcm-url="$URL" "$log" > /dev/null 2>&1 & rp=$!
  wait $l || true
  rc=$(json "$TMP/$name/summary.json" '.lockstep.completed | if . then 0 else 1 end')
  kill $rp 2> /dev/null || true
  wait $rp 2> /dev/null || true
}
replay_into replayed "$LOGDIR/old.lcmlog"
completed_identical replayed
n=$(json "$TMP/replayed/summary.json" .lockstep.foreign_messages)
[ "$n" -gt 100 ] || fail "replayed: only $n foreign messages counted"
pass "replayed log of an earlier run: $n foreign messages counted and ignored; identical to feeddrive-sim"

lcm-logger --lcm-url="$URL" --channel='FD_.*' --force "$LOGDIR/signed.lcmlog" > /dev/null 2>&1 & lg=$!
wait_on_bus $lg
launch signed --key "$KEY"
kill -INT $lg; wait $lg || true
completed_identical signed
replay_into replayed_key "$LOGDIR/signed.lcmlog" --key "$KEY"
completed_identical replayed_key
n=$(json "$TMP/replayed_key/summary.json" .lockstep.foreign_messages)
[ "$n" -gt 100 ] || fail "replayed_key: only $n foreign messages counted"
pass "with --key, a replayed signed log (valid macs, old run id): $n foreign messages ignored; identical"

# 3b. The same --run-id for both runs, with --key.
lcm-logger --lcm-url="$URL" --channel='FD_.*' --force "$LOGDIR/signed_fixed.lcmlog" > /dev/null 2>&1 & lg=$!
wait_on_bus $lg
launch signed_fixed --key "$KEY" --run-id 4242
kill -INT $lg; wait $lg || true
completed_identical signed_fixed
replay_into replayed_fixed "$LOGDIR/signed_fixed.lcmlog" --key "$KEY" --run-id 4242
completed_identical replayed_fixed
n=$(json "$TMP/replayed_fixed/summary.json" .lockstep.foreign_messages)
[ "$n" -gt 100 ] || fail "replayed_fixed: only $n foreign messages counted (a replay with the run id reused)"
[ "$(json "$TMP/replayed_fixed/summary.json" .lockstep.run_id)" != "$(json "$TMP/signed_fixed/summary.json" .lockstep.run_id)" ] ||
  fail "replayed_fixed: the same run id on the wire as the earlier run with --run-id 4242"
pass "with --key and --run-id reused, a replayed signed log is another run's: $n foreign messages ignored; identical"

# 5. The malformed datagrams, all through a run.
timeout 300 "$BUILD/tests/fd-test-peer" malformed --seconds 20 --lcm-url "$URL" > "$TMP/peer.log" 2>&1 & peer_pid=$!
wait_on_bus $peer_pid
launch malformed
kill $peer_pid 2> /dev/null || true
wait $peer_pid 2> /dev/null || true
[ "$rc" = 0 ] || { tail -5 "$TMP/malformed.log" >&2; fail "malformed: launch exited $rc"; }
completed_identical malformed
for c in FD_STATUS FD_REF FD_CMD FD_STATE; do
  n=$(json "$TMP/malformed/summary.json" ".lockstep.invalid_messages_by_channel.$c // 0")
  [ "$n" -gt 0 ] || fail "malformed: no invalid message counted on $c ($(json "$TMP/malformed/summary.json" .lockstep.invalid_messages_by_channel))"
done
pass "malformed datagrams through a run: counted $(jq -c .lockstep.invalid_messages_by_channel "$TMP/malformed/summary.json") and dropped; identical to feeddrive-sim"

# 6. A forged "running" heartbeat of the monitor.
timeout 300 "$BUILD/tests/fd-test-peer" fake-monitor --seconds 120 --lcm-url "$URL" > "$TMP/peer.log" 2>&1 & peer_pid=$!
wait_on_bus $peer_pid
start=$(date +%s)
launch fake_monitor --linger 60
took=$(( $(date +%s) - start ))
kill $peer_pid 2> /dev/null || true
wait $peer_pid 2> /dev/null || true
[ "$rc" = 0 ] || { tail -5 "$TMP/fake_monitor.log" >&2; fail "fake_monitor: launch exited $rc"; }
# 30 s: the run itself takes a few seconds even on a loaded machine; a held linger takes 60 s.
[ "$took" -lt 30 ] || fail "fake_monitor: the launch took $took s with --linger 60: the forged heartbeat held the run open"
pass "a forged 'running' heartbeat of the monitor: the run ended in $took s (--linger 60)"

# 7. Forged heartbeats that go back, claim the future, or seem to progress.
timeout 300 "$BUILD/tests/fd-test-peer" fake-heartbeats --seconds 120 --lcm-url "$URL" > "$TMP/peer.log" 2>&1 & peer_pid=$!
wait_on_bus $peer_pid
start=$(date +%s)
launch fake_heartbeats --linger 60
took=$(( $(date +%s) - start ))
kill $peer_pid 2> /dev/null || true
wait $peer_pid 2> /dev/null || true
[ "$rc" = 0 ] || { tail -5 "$TMP/fake_heartbeats.log" >&2; fail "fake_heartbeats: launch exited $rc"; }
completed_identical_despite fake_heartbeats
! grep -q "restarted" "$TMP/fake_heartbeats.log" || fail "fake_heartbeats: a forged heartbeat was taken for a restart"
# 30 s: as in case 6; an attached monitor may hold the linger 2 s at most (node.hpp kAttachedHoldS).
[ "$took" -lt 30 ] || fail "fake_heartbeats: the launch took $took s with --linger 60: a forged heartbeat held the run open"
pass "forged heartbeats (acked 10^9, plant at 10^9, an attached monitor 'running'): identical, $(json "$TMP/fake_heartbeats/summary.json" .lockstep.conflicts) conflicts ignored, ended in $took s"

# 8. The run's own signed heartbeats, replayed through the run.
timeout 300 "$BUILD/tests/fd-test-peer" replay-status --seconds 120 --lcm-url "$URL" > "$TMP/peer.log" 2>&1 & peer_pid=$!
wait_on_bus $peer_pid
launch replay_status --key "$KEY"
kill $peer_pid 2> /dev/null || true
wait $peer_pid 2> /dev/null || true
grep -q "replaying" "$TMP/peer.log" || fail "replay_status: the peer replayed nothing ($(cat "$TMP/peer.log"))"
[ "$rc" = 0 ] || { tail -5 "$TMP/replay_status.log" >&2; fail "replay_status: launch exited $rc"; }
completed_identical_despite replay_status
pass "the run's own signed heartbeats replayed with --key: identical ($(tail -n 1 "$TMP/peer.log"))"

# 9. Unsigned forgeries in a keyed run.
for mode in fake-heartbeats junk; do
  timeout 300 "$BUILD/tests/fd-test-peer" $mode --seconds 120 --lcm-url "$URL" > "$TMP/peer.log" 2>&1 & peer_pid=$!
  wait_on_bus $peer_pid
  launch "keyed_$mode" --key "$KEY"
  kill $peer_pid 2> /dev/null || true
  wait $peer_pid 2> /dev/null || true
  completed_identical_despite "keyed_$mode"
  n=$(json "$TMP/keyed_$mode/summary.json" .lockstep.unauthenticated_messages)
  [ "$n" -gt 0 ] || fail "keyed_$mode: no unauthenticated message counted"
  pass "unsigned $mode in a keyed run: $n unauthenticated messages dropped; identical"
done

# 4. Concurrent runs.
timeout 300 feeddrive-launch "$scen" --out "$TMP/first" --no-plots -q --lcm-url "$URL" > "$TMP/first.log" 2>&1 & first=$!
plant_up $first
start=$(date +%s%N)
launch second
took_ms=$(( ($(date +%s%N) - start) / 1000000 ))
[ "$rc" = 2 ] || { cat "$TMP/second.log" >&2; fail "second launch on the same group exited $rc, expected 2"; }
err=$(grep -c "" "$TMP/second.log")
[ "$err" -le 2 ] || { cat "$TMP/second.log" >&2; fail "second launch: $err lines of output"; }
grep -q "error: another run holds FD_\* on .* (run id [0-9]*, its plant .*): give this one another --prefix" "$TMP/second.log" ||
  { cat "$TMP/second.log" >&2; fail "second launch: no one-line 'another run holds' error"; }
[ "$took_ms" -lt 5000 ] || fail "second launch took $took_ms ms to refuse"
[ -e "$TMP/second" ] && fail "the refused launch left an output folder"
echo "  $(grep error: "$TMP/second.log")"
launch other_prefix --prefix FD2
wait $first || fail "the first run failed while a second ran with another prefix: $(tail -3 "$TMP/first.log")"
rc=0
completed_identical first
completed_identical other_prefix
pass "concurrent runs: the second refused in $took_ms ms with one line; with --prefix FD2 both completed identical"

# Both past the check at the same instant: each run ignores the other's messages.
launch race_a --start-timeout 60 & a=$!
launch race_b --start-timeout 60 & b=$!
rc_a=0; wait $a || rc_a=$?
rc_b=0; wait $b || rc_b=$?
for r in race_a race_b; do
  if [ -f "$TMP/$r/summary.json" ]; then
    rc=0
    completed_identical $r
    echo "  $r: completed, $(json "$TMP/$r/summary.json" .lockstep.foreign_messages) foreign messages ignored"
  else
    grep -q "another run holds" "$TMP/$r.log" || { cat "$TMP/$r.log" >&2; fail "$r: neither completed nor refused"; }
    echo "  $r: refused (the other run's plant was already up)"
  fi
done
[ -f "$TMP/race_a/summary.json" ] || [ -f "$TMP/race_b/summary.json" ] || fail "race: neither run completed"
pass "two launches at once: each completed identical or refused in one line"
