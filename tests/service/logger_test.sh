#!/usr/bin/env bash
# Capture with the stock lcm-logger: record a run, convert the log with feeddrive-log2csv, and
# require the same timeseries.csv as the monitor's, every step present. Then play the log back
# with the stock lcm-logplayer to a monitor in --attach mode: same file again. Then the same with
# the monitor's own log (feeddrive-launch --lcm-log), which costs the run no extra process.
# Stock lcm-logger keeps LCM's default 30-message subscription queue and drops when it falls
# behind a 10 kHz lockstep run on a busy machine, so it runs with real-time priority (chrt), as
# docs/lcm-contract.md recommends.
source "$(dirname "$0")/lib.sh" "$@"
scen=$SRC/scenarios/paper/smc_bl_ramp_all_forces.yaml
prio=(chrt -f 20)
"${prio[@]}" true 2>/dev/null || { echo "note: no real-time priority available; logging without it"; prio=(); }
# The stock logger's drops are its own (LCM's 30-message queue), not what is tested here: a
# recording it dropped from (log2csv names the missing steps) is made once more.
for attempt in 1 2; do
  "${prio[@]}" lcm-logger --lcm-url="$URL" --channel='FD_.*' --force "$LOGDIR/run.lcmlog" 2> "$TMP/logger.err" & lg=$!
  wait_on_bus $lg
  # The run on CPU 0, the logger (real-time priority) free to take the other core: on a loaded
  # 2-core machine a run that shares both cores with it outruns it (the logger drops, silently).
  timeout 300 feeddrive-launch "$scen" --out "$TMP/mon" --no-plots -q --lcm-url "$URL" --cpus 0
  sleep 0.5
  kill -INT $lg; wait $lg || true
  timeout 120 feeddrive-log2csv "$LOGDIR/run.lcmlog" --scenario "$scen" --out "$TMP/conv" -q 2> "$TMP/conv.err"
  grep -q "steps missing" "$TMP/conv.err" || break
  [ $attempt = 1 ] || { cat "$TMP/conv.err" >&2; fail "the stock lcm-logger dropped messages twice"; }
  echo "note: the stock lcm-logger dropped messages ($(cat "$TMP/conv.err")); recording once more"
done
same_csv "$TMP/mon/timeseries.csv" "$TMP/conv/timeseries.csv"
rows=$(( $(wc -l < "$TMP/conv/timeseries.csv") - 1 ))
[ "$rows" = 10000 ] || fail "$rows rows, expected 10000"
pass "lcm-logger log converted: $rows rows, identical to the monitor's"

timeout 120 feeddrive-monitor "$scen" --out "$TMP/replay" --no-plots -q --attach --step-timeout 3 --lcm-url "$URL" & m=$!
wait_on_bus $m
timeout 120 lcm-logplayer --lcm-url="$URL" "$LOGDIR/run.lcmlog" > /dev/null 2>&1
wait $m || fail "the attached monitor failed"
same_csv "$TMP/mon/timeseries.csv" "$TMP/replay/timeseries.csv"
pass "lcm-logplayer playback recorded by an attached monitor: identical"

# The monitor's own log: the same file from feeddrive-log2csv and from an lcm-logplayer playback.
timeout 300 feeddrive-launch "$scen" --out "$TMP/mon2" --no-plots -q --lcm-url "$URL" --lcm-log "$LOGDIR/mon.lcmlog"
timeout 120 feeddrive-log2csv "$LOGDIR/mon.lcmlog" --scenario "$scen" --out "$TMP/conv2" -q
same_csv "$TMP/mon2/timeseries.csv" "$TMP/conv2/timeseries.csv"
same_csv "$TMP/mon/timeseries.csv" "$TMP/mon2/timeseries.csv"
timeout 120 feeddrive-monitor "$scen" --out "$TMP/replay2" --no-plots -q --attach --step-timeout 3 --lcm-url "$URL" & m=$!
wait_on_bus $m
timeout 120 lcm-logplayer --lcm-url="$URL" "$LOGDIR/mon.lcmlog" > /dev/null 2>&1
wait $m || fail "the attached monitor failed on the monitor's log"
same_csv "$TMP/mon2/timeseries.csv" "$TMP/replay2/timeseries.csv"
pass "feeddrive-launch --lcm-log: converted and played back, identical ($(stat -c %s "$LOGDIR/mon.lcmlog") bytes)"

# A corrupt log gets a one-line error naming the file, and exit 2.
head -c 100000 "$LOGDIR/run.lcmlog" > "$TMP/bad.lcmlog"
printf 'garbage-garbage-garbage' >> "$TMP/bad.lcmlog"
head -c 50000 "$LOGDIR/run.lcmlog" | tail -c 20000 >> "$TMP/bad.lcmlog"
set +e
feeddrive-log2csv "$TMP/bad.lcmlog" --scenario "$scen" --out "$TMP/bad" -q 2> "$TMP/bad.err"; rc=$?
set -e
[ $rc -ne 0 ] || fail "a corrupt log converted with exit 0"
[ "$(wc -l < "$TMP/bad.err")" = 1 ] || { cat "$TMP/bad.err"; fail "not one line"; }
grep -q "bad.lcmlog" "$TMP/bad.err" || fail "the error does not name the file"
pass "corrupt log: exit $rc, $(cat "$TMP/bad.err")"
