#!/usr/bin/env bash
# Capture with the stock lcm-logger: record a run, convert the log with feeddrive-log2csv, and
# require the same timeseries.csv as the monitor's, every step present. Then play the log back
# with the stock lcm-logplayer to a monitor in --attach mode: same file again. Then the same with
# the monitor's own log (feeddrive-launch --lcm-log), which costs the run no extra process.
# The stock lcm-logger keeps LCM's default 30-message subscription queue and drops silently when
# it falls behind. Lossless by design: feeddrive-launch sees the logger on the bus and paces the run
# to what it records without loss (service/loggers.hpp): 1000 steps/s at real-time priority
# (chrt -f 20, where permitted, as docs/lcm-contract.md recommends), 500 at normal priority;
# measured with bench/logger_pace_bench.sh under stress-ng on both cores (20 of 20 runs complete
# at 1000 with chrt). So the test records once: no retry.
source "$(dirname "$0")/lib.sh" "$@"
scen=$SRC/scenarios/paper/smc_bl_ramp_all_forces.yaml
prio=(chrt -f 20) pace=1000
"${prio[@]}" true 2>/dev/null || { echo "note: no real-time priority for lcm-logger here; it runs at normal priority (paced to 500 steps/s)"; prio=(); pace=500; }
"${prio[@]}" lcm-logger --lcm-url="$URL" --channel='FD_.*' --force "$LOGDIR/run.lcmlog" 2> "$TMP/logger.err" & lg=$!
wait_on_bus $lg
timeout 300 feeddrive-launch "$scen" --out "$TMP/mon" --no-plots --lcm-url "$URL" 2> "$TMP/launch.err"
grep -q "lcm-logger (pid [0-9]*, [a-z-]* priority) on the bus: the run is paced to $pace steps/s" "$TMP/launch.err" ||
  { cat "$TMP/launch.err"; fail "the launcher did not pace the run for the stock logger"; }
[ "$(json "$TMP/mon/summary.json" '.lockstep.stock_loggers.seen | length')" -ge 1 ] || fail "the monitor did not see the logger"
[ "$(json "$TMP/mon/summary.json" '.lockstep.stock_loggers.faster_than_it_records')" = false ] || fail "paced run reported too fast"
stop_logger $lg "$LOGDIR/run.lcmlog" FD  # once it has the whole run (lib.sh)
timeout 120 feeddrive-log2csv "$LOGDIR/run.lcmlog" --scenario "$scen" --out "$TMP/conv" -q 2> "$TMP/conv.err"
! grep -q "steps missing" "$TMP/conv.err" || { cat "$TMP/conv.err" >&2; fail "the stock lcm-logger dropped messages of a paced run"; }
same_csv "$TMP/mon/timeseries.csv" "$TMP/conv/timeseries.csv"
rows=$(( $(wc -l < "$TMP/conv/timeseries.csv") - 1 ))
[ "$rows" = 10000 ] || fail "$rows rows, expected 10000"
pass "lcm-logger log converted: $rows rows, identical to the monitor's"

# Unpaced on purpose (--max-rate 0) with a stock logger on the bus: the monitor says that the steps
# went out faster than the logger records (its log may miss steps) in one line and in summary.json.
lcm-logger --lcm-url="$URL" --channel='FD_.*' --force "$LOGDIR/fast.lcmlog" 2> /dev/null & lg2=$!
wait_on_bus $lg2
timeout 300 feeddrive-launch "$scen" --out "$TMP/fast" --no-plots -q --lcm-url "$URL" --max-rate 0 2> "$TMP/fast.err"
kill -INT $lg2; wait $lg2 || true
[ "$(grep -c "faster\|its log may miss steps" "$TMP/fast.err")" = 1 ] || { cat "$TMP/fast.err"; fail "no single line about the unpaced run"; }
[ "$(json "$TMP/fast/summary.json" '.lockstep.stock_loggers.faster_than_it_records')" = true ] || fail "unpaced run not reported"
pass "unpaced with a stock logger on the bus: $(cat "$TMP/fast.err")"

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
