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

# 3. SIGKILL of the launcher.
feeddrive-launch s.yaml --out killed --no-plots -q --lcm-url "$URL" > killed.log 2>&1 & launcher=$!
for _ in $(seq 200); do [ "$(running_children $launcher)" = 4 ] && break; sleep 0.05; done
[ "$(running_children $launcher)" = 4 ] || fail "the launcher did not start four processes within 10 s"
kids=$(pgrep -P $launcher | tr '\n' ' ')
sleep 1  # mid-run
kill -KILL $launcher
wait $launcher 2> /dev/null || true
left=4
for _ in $(seq 100); do
  left=0
  for k in $kids; do kill -0 "$k" 2> /dev/null && left=$((left + 1)); done
  [ "$left" = 0 ] && break
  sleep 0.05
done
[ "$left" = 0 ] || fail "$left of the launcher's processes still running 5 s after it was killed"
pass "SIGKILL of feeddrive-launch: its four processes stopped with it"

# 4. SIGKILL of the monitor.
rc=0
feeddrive-launch s.yaml --out mon --no-plots --lcm-url "$URL" --step-timeout 2 > mon.log 2>&1 & launcher=$!
for _ in $(seq 200); do [ "$(running_children $launcher)" = 4 ] && break; sleep 0.05; done
monitor=$(pgrep -P $launcher -f "feeddrive-monitor " || true)
[ -n "$monitor" ] || fail "no monitor under the launcher"
# Mid-run: once the monitor's staging record holds 64 kB of rows (past any write buffer), not
# after a fixed sleep (a loaded machine may not have started the run by then).
for _ in $(seq 400); do
  [ -n "$(find . -maxdepth 2 -path "./.mon.partial-$monitor-*/timeseries.csv" -size +64k 2> /dev/null)" ] && break
  sleep 0.05
done
kill -KILL "$monitor"
wait $launcher || rc=$?
[ "$rc" = 1 ] || { tail -5 mon.log >&2; fail "monitor killed: launch exited $rc, expected 1"; }
tail -n 1 mon.log | grep -q "the monitor was killed: its record up to then .* is in $TMP/mon.incomplete-1" ||
  { tail -5 mon.log >&2; fail "the launcher's last line does not name the monitor's partial record"; }
[ -d mon.incomplete-1 ] || fail "no mon.incomplete-1"
rows=$(grep -c "" mon.incomplete-1/timeseries.csv || true)
[ "$rows" -gt 1 ] || fail "the partial record has no rows"
pass "SIGKILL of the monitor: $(tail -n 1 mon.log | sed 's/.*\] //') ($rows lines)"
