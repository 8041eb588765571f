#!/usr/bin/env bash
# Ctrl-C ends any phase within a second (issue 13, point 8), the same way in every tool: exit
# 130 (128 + SIGINT), exactly one line on stderr ("error: interrupted by SIGINT"), and no staging
# folder (.NAME.partial-*) left behind. Phases: feeddrive-sim simulating and plotting,
# feeddrive-fit fitting and plotting, feeddrive-launch (and its four processes) running. The
# monitor keeps what it recorded: launch's folder then holds a complete, marked output with
# `completed: false`.
source "$(dirname "$0")/lib.sh" "$@"
cd "$TMP"
# A 1.5 s, 10 kHz run with plots: about 1 s of simulation and several of plotting.
scen=$SRC/scenarios/paper/smc_sine.yaml

# interrupt NAME PID WHEN: sends SIGINT to PID once WHEN (a shell test) holds, within 30 s, then
# checks exit code, time to exit, stderr ($TMP/NAME.err) and that no staging folder remains. WHEN
# is the phase under test reached (CPU time spent computing, a child started, a step of the run
# on the bus), never a fixed sleep: a sleep long enough on a loaded machine is past the phase on
# a fast one.
interrupt() {
  local name=$1 pid=$2 when=$3 t0 t1 rc
  wait_until 30 "$name: the phase to interrupt" eval "$when"
  t0=$(date +%s%N)
  kill -INT "$pid"
  rc=0
  wait "$pid" || rc=$?
  t1=$(date +%s%N)
  local ms=$(((t1 - t0) / 1000000))
  [ "$rc" = 130 ] || fail "$name: exit $rc after SIGINT (expected 130): $(cat "$TMP/$name.err")"
  # Within a second, as the issue asks; measured here without the 20 parallel tests' load
  # (RUN_SERIAL in tests/CMakeLists.txt).
  [ "$ms" -lt 1000 ] || fail "$name: took $ms ms to exit after SIGINT"
  [ "$(wc -l < "$TMP/$name.err")" = 1 ] || fail "$name: stderr is not one line: $(cat "$TMP/$name.err")"
  grep -q "^error: interrupted by SIGINT" "$TMP/$name.err" || fail "$name: stderr: $(cat "$TMP/$name.err")"
  [ -z "$(find "$TMP" -maxdepth 2 -name '.*.partial-*')" ] || fail "$name: a staging folder remains"
  pass "$name: exit 130 after $ms ms, one line, nothing half-written"
}
gnuplot_running() { pgrep -P "$1" gnuplot > /dev/null; }

feeddrive-sim "$scen" --out sim_run -q 2> sim_run.err &
p=$!
interrupt sim_run $p "cpu_ms_at_least $p 100"  # under test: simulating (loading takes a few ms of CPU)
[ ! -e sim_run ] || fail "sim_run: an output folder was created"

feeddrive-sim "$scen" --out sim_plot -q 2> sim_plot.err &
p=$!
interrupt sim_plot $p "gnuplot_running $p"
[ ! -e sim_plot ] || fail "sim_plot: an output folder was created"
pgrep gnuplot > /dev/null && fail "sim_plot: gnuplot still runs"

# The fit: 4 s of the docs/fit.md "real drive" (two hidden effects), which takes seconds to fit,
# interrupted while it fits and again while it plots.
cp "$SRC/scenarios/fit/rich_reference.csv" .
sed 's/^duration:.*/duration: 4.0/' "$SRC/scenarios/fit/truth_cogging.yaml" > truth.yaml
timeout 120 feeddrive-sim truth.yaml --out fitdata --no-plots -q
cut -d, -f1,7,13 fitdata/timeseries.csv | sed '1s/.*/t,x,u/' > fitdata.csv
feeddrive-fit -s "$SRC/scenarios/fit/model.yaml" -d fitdata.csv --out fit_run -q > /dev/null 2> fit_run.err &
p=$!
interrupt fit_run $p "cpu_ms_at_least $p 300"  # under test: fitting (seconds of CPU; loading takes ms)
[ ! -e fit_run ] || fail "fit_run: an output folder was created"
feeddrive-fit -s "$SRC/scenarios/fit/model.yaml" -d fitdata.csv --out fit_plot -q > /dev/null 2> fit_plot.err &
p=$!
interrupt fit_plot $p "gnuplot_running $p"
[ ! -e fit_plot ] || fail "fit_plot: an output folder was created"

# feeddrive-launch: four processes in lockstep; SIGINT to the launcher is forwarded to each.
feeddrive-launch "$scen" --out launch_run --lcm-url "$URL" --no-plots -q 2> launch_run.err &
p=$!
# Under test: mid-run, once step 3000 (of 15,000) is on the bus: the monitor has recorded steps.
interrupt launch_run $p "wait_bus_step 3000"
[ -z "$(pgrep -P $p)" ] || fail "launch_run: a child process still runs"
[ "$(json launch_run/summary.json .lockstep.completed)" = false ] || fail "launch_run: summary does not say completed: false"
json launch_run/summary.json .lockstep.failure | grep -q "interrupted by SIGINT" || fail "launch_run: the failure is not the interrupt"
pass "launch_run: the monitor kept $(json launch_run/summary.json .steps) recorded steps"

# An interrupted rerun into a complete earlier output: the earlier output stays as it was, the
# interrupted record goes beside it (launch_run2.incomplete-1). It once replaced the earlier one.
timeout 120 feeddrive-launch "$scen" --out launch_run2 --lcm-url "$URL" --no-plots -q
[ "$(json launch_run2/summary.json .lockstep.completed)" = true ] || fail "launch_run2: the first run did not complete"
before=$(md5sum < launch_run2/timeseries.csv)
feeddrive-launch "$scen" --out launch_run2 --lcm-url "$URL" --no-plots -q 2> launch_run2.err &
p=$!
interrupt launch_run2 $p "wait_bus_step 3000"  # as launch_run: mid-run
[ "$(md5sum < launch_run2/timeseries.csv)" = "$before" ] || fail "launch_run2: the earlier output was changed"
[ "$(json launch_run2/summary.json .lockstep.completed)" = true ] || fail "launch_run2: the earlier summary was replaced"
[ "$(json launch_run2.incomplete-1/summary.json .lockstep.completed)" = false ] ||
  fail "launch_run2: the interrupted record is not in launch_run2.incomplete-1"
pass "launch_run2: the earlier output kept, the interrupted record ($(json launch_run2.incomplete-1/summary.json .steps) steps) beside it"

# Ctrl-C while the launcher starts its processes (its first child forked, the others to come): a
# signal that reached a child between fork and exec was lost, and the child ran on to its 10 s
# start timeout.
feeddrive-launch "$scen" --out launch_early --lcm-url "$URL" --no-plots -q 2> launch_early.err &
p=$!
interrupt launch_early $p "pgrep -P $p > /dev/null"  # under test: the launcher starting its processes
[ -z "$(pgrep -P $p)" ] || fail "launch_early: a child process still runs"

# Ctrl-C while the monitor draws the plots of a complete run: what it recorded cannot be made
# again, so the data go in place without the plots (it once threw the whole record away).
mkdir -p slowplot
printf '#!/bin/sh\ntouch "%s/slowplot/started"\nexec sleep 30\n' "$TMP" > slowplot/gnuplot
chmod +x slowplot/gnuplot
PATH="$TMP/slowplot:$PATH" feeddrive-launch "$scen" --out launch_plot --lcm-url "$URL" -q 2> launch_plot.err &
p=$!
interrupt launch_plot $p "[ -e slowplot/started ]"
[ "$(json launch_plot/summary.json .lockstep.completed)" = true ] || fail "launch_plot: the complete record was not kept"
[ "$(($(wc -l < launch_plot/timeseries.csv) - 1))" = "$(json launch_plot/summary.json .steps)" ] ||
  fail "launch_plot: timeseries.csv does not hold every step"
pass "launch_plot: interrupted while plotting, the complete record ($(json launch_plot/summary.json .steps) steps) kept"
