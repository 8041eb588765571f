#!/usr/bin/env bash
# Files and signals that must not take a run down (issue 19, points 5, 6 and 7; docs/security.md):
#   1. paths checked before any process starts: a FIFO as --key, --lcm-log or scenario, a folder
#      or a path with a missing parent as --lcm-log each get exit 2 and one line, at once (a FIFO
#      never blocks open()), and no process is started;
#   2. one run, one scenario: a process given the launcher's --scenario-hash refuses a file
#      that hashes otherwise (exit 2, one line);
#   3. children die with their launcher: after SIGKILL of feeddrive-launch, none of its four
#      processes is left within 5 s;
#   4. a SIGKILLed monitor: the launcher moves its record so far beside --out (DIR.incomplete-N)
#      and names it in its last line.
source "$(dirname "$0")/lib.sh" "$@"
cd "$TMP"
cp "$SRC/scenarios/paper/beyond_jerk_limited.yaml" s.yaml
sed -i 's/^duration:.*/duration: 30.0/' s.yaml  # long enough to be killed mid-run
mkfifo fifo
head -c 32 /dev/urandom > key
chmod 600 key

# refused CASE EXPECTED ARGS...: exit 2, one line matching EXPECTED, within 5 s (the checks come
# before the launcher starts any process: service/apps/launch_main.cpp).
refused() {
  local name=$1 want=$2 rc=0 start took
  shift 2
  start=$(date +%s%N)
  timeout 20 feeddrive-launch "$@" > "$name.log" 2>&1 || rc=$?
  took=$(( ($(date +%s%N) - start) / 1000000 ))
  [ "$rc" = 2 ] || { cat "$name.log" >&2; fail "$name: exit $rc, expected 2"; }
  [ "$(grep -c "" "$name.log")" = 1 ] || { cat "$name.log" >&2; fail "$name: not one line"; }
  grep -q -- "$want" "$name.log" || { cat "$name.log" >&2; fail "$name: the line does not say '$want'"; }
  # 5 s: a refusal reads a few small files; a FIFO that blocked open() would hang to the timeout.
  [ "$took" -lt 5000 ] || fail "$name: took $took ms"
  pass "$name: $(cat "$name.log") ($took ms)"
}
refused fifo_key "key fifo: not a regular file (a FIFO)" s.yaml --out o --no-plots -q --lcm-url "$URL" --key fifo
refused fifo_log "lcm-log fifo: is a FIFO" s.yaml --out o --no-plots -q --lcm-url "$URL" --lcm-log fifo
refused fifo_scenario "fifo: the scenario file is a FIFO" fifo --out o --no-plots -q --lcm-url "$URL"
refused dir_log "lcm-log $TMP: is a folder" s.yaml --out o --no-plots -q --lcm-url "$URL" --lcm-log "$TMP"
refused missing_parent "its folder $TMP/nowhere does not exist" s.yaml --out o --no-plots -q --lcm-url "$URL" --lcm-log "$TMP/nowhere/run.lcmlog"
# /proc takes no new file, although root may write in it (access() says yes): the launcher
# creates the file and removes it again before anything starts (issue 19's review).
refused proc_log "lcm-log /proc/fd-run.lcmlog: cannot be created" s.yaml --out o --no-plots -q --lcm-url "$URL" --lcm-log /proc/fd-run.lcmlog
refused proc_file_log "lcm-log /proc/version: is a kernel pseudo file" s.yaml --out o --no-plots -q --lcm-url "$URL" --lcm-log /proc/version
# A file that is not an LCM log (here the run's own scenario) is never overwritten by --lcm-log.
cp s.yaml s_before.yaml
refused clobber_log "lcm-log s.yaml: exists and is not a file this option writes" s.yaml --out o --no-plots -q --lcm-url "$URL" --lcm-log s.yaml
cmp -s s.yaml s_before.yaml || fail "--lcm-log s.yaml changed the scenario"
[ -e o ] && fail "a refused launch left an output folder"

# 2. A scenario other than the launcher's.
rc=0
feeddrive-plant s.yaml --lcm-url "$URL" -q --scenario-hash "$(echo other | sha256sum | cut -c1-64)" > hash.log 2>&1 || rc=$?
[ "$rc" = 2 ] || { cat hash.log >&2; fail "another scenario's hash: exit $rc, expected 2"; }
grep -q "not the scenario this run started with" hash.log || { cat hash.log >&2; fail "hash: no one-line refusal"; }
rc=0
timeout 20 feeddrive-plant s.yaml --lcm-url "$URL" -q --start-timeout 1 --scenario-hash "$(sha256sum s.yaml | cut -c1-64)" > hash_ok.log 2>&1 || rc=$?
grep -q "not the scenario" hash_ok.log && fail "the scenario's own hash was refused"
pass "one run, one scenario: $(cat hash.log)"

# running_children PID: the feeddrive processes whose parent is PID.
running_children() { pgrep -P "$1" -f "feeddrive-(plant|controller|trajectory|monitor) " | wc -l; }
# four_running PID: the launcher PID has started its four processes.
four_running() { [ "$(running_children "$1")" = 4 ]; }
# none_alive PID...: none of the processes PID... runs any more.
none_alive() {
  local k
  for k in "$@"; do ! kill -0 "$k" 2> /dev/null || return 1; done
}

# 3. SIGKILL of the launcher.
feeddrive-launch s.yaml --out killed --no-plots --lcm-url "$URL" > killed.log 2>&1 & launcher=$!
wait_until 10 "the launcher started its four processes" four_running $launcher
kids=$(pgrep -P $launcher | tr '\n' ' ')
wait_step killed.log 1000  # the fault under test: the launcher killed mid-run, once step 1000 is recorded
kill -KILL $launcher
wait $launcher 2> /dev/null || true
wait_until 5 "the launcher's processes stopped after it was killed (still running: $kids)" none_alive $kids
pass "SIGKILL of feeddrive-launch: its four processes stopped with it"

# 4. SIGKILL of the monitor, mid-run, paced at 500 steps/s: the staged record goes beside --out
# and holds every step up to the last second (the monitor hands its rows to the file every
# second; issue 19's review found 0 bytes after 3,000 steps).
rc=0
feeddrive-launch s.yaml --out mon --no-plots --lcm-url "$URL" --step-timeout 2 --max-rate 500 > mon.log 2>&1 & launcher=$!
wait_until 10 "the launcher started its four processes" four_running $launcher
monitor=$(pgrep -P $launcher -f "feeddrive-monitor " || true)
[ -n "$monitor" ] || fail "no monitor under the launcher"
# Killed once its progress line says step 1500 (3 s of steps), whatever the machine's load.
wait_step mon.log 1500
at=$(monitor_step mon.log)
kill -KILL "$monitor"
wait $launcher || rc=$?
[ "$rc" = 1 ] || { tail -5 mon.log >&2; fail "monitor killed: launch exited $rc, expected 1"; }
tail -n 1 mon.log | grep -q "the monitor was killed: its record up to then .* is in $TMP/mon.incomplete-1" ||
  { tail -5 mon.log >&2; fail "the launcher's last line does not name the monitor's partial record"; }
[ -d mon.incomplete-1 ] || fail "no mon.incomplete-1"
rows=$(( $(grep -c "" mon.incomplete-1/timeseries.csv || true) - 1 ))
# At most one second (500 steps) lost, and 100 more for the progress line's own lag.
[ "$rows" -ge $(( at - 600 )) ] || fail "the partial record has $rows rows; the monitor had passed step $at"
pass "SIGKILL of the monitor at step $at: $(tail -n 1 mon.log | sed 's/.*\] //') ($rows rows kept)"

# 5. An external controller started by hand with another scenario file (issue 19's review: it
# ran, and the run passed with the record of the other file): refused with exit 2 and one line
# naming both hashes once the monitor's run_info_t names the run's scenario; the run fails.
sed 's/^name:.*/name: another/' s.yaml > another.yaml
rc=0
timeout 60 feeddrive-launch s.yaml --out ext --no-plots -q --lcm-url "$URL" --external controller --run-id 4711 \
  --start-timeout 5 > ext.log 2>&1 & launcher=$!
crc=0
timeout 30 feeddrive-controller another.yaml --lcm-url "$URL" --run-id 4711 -q > ctl.log 2>&1 || crc=$?
wait $launcher || rc=$?
[ "$crc" = 2 ] || { cat ctl.log >&2; fail "a controller with another scenario: exit $crc, expected 2"; }
[ "$(grep -c "" ctl.log)" = 1 ] || { cat ctl.log >&2; fail "a controller with another scenario: not one line"; }
grep -q "this controller's scenario (sha256 .*) is not the run's" ctl.log || { cat ctl.log >&2; fail "the refusal does not name the scenarios"; }
[ "$rc" != 0 ] || fail "the run passed with a controller of another scenario"
[ -f ext/summary.json ] && [ "$(jq -r .lockstep.completed ext/summary.json)" = true ] && fail "ext: completed"
pass "an external controller with another scenario: $(cat ctl.log | sed 's/.*\] //') (the launch exited $rc)"
