#!/usr/bin/env bash
# Output folders are safe, end to end, through feeddrive-sim, feeddrive-fit and feeddrive-launch
# (and its monitor):
#   1. names are never code: a scenario `name` and scenario, data and output file names built to
#      run `touch MARK` through gnuplot (quotes, system, backquotes) or a shell run nothing, and
#      the run succeeds with its plots (titles show the sanitised name);
#   2. `--out prev/` replaces an earlier output in place; a folder that is not a feeddrive output
#      (even with a summary.json) is refused with exit 2 and one line, before any process
#      starts, and left untouched;
#   3. feeddrive-launch exits non-zero when its monitor cannot write the results (here: gnuplot
#      fails), and the previous output survives.
source "$(dirname "$0")/lib.sh" "$@"
scen=$SRC/tests/service/scenarios/short_jerk.yaml
work=$TMP/work   # every command runs here: a relative "touch MARK" from a shell would land here
mkdir -p "$work"
cd "$work"
no_mark() {  # no MARK anywhere under $TMP
  local found
  found=$(find "$TMP" -name MARK -print)
  [ -z "$found" ] || fail "$1: a name ran as a command: $found"
}
pngs() { for f in "$@"; do [ -s "$f" ] || fail "missing $f"; done; }

# ---- 1. names are never code
evil_name="x'; system 'touch $TMP/MARK'; print '\`touch $TMP/MARK\`@x"
sed "s|^name: short_jerk|name: \"$evil_name\"|" "$scen" > "$work/named.yaml"
grep -q "system 'touch" "$work/named.yaml" || fail "test setup: name not replaced"
sed '/^name:/d' "$scen" > "$work/a'; system 'touch MARK'; print '.yaml"
sed '/^name:/d' "$scen" > "$work/\`touch MARK\`.yaml"

k=0
for s in "$work/named.yaml" "$work/a'; system 'touch MARK'; print '.yaml" "$work/\`touch MARK\`.yaml"; do
  k=$((k + 1))
  out="$work/sim o'; touch MARK; echo '$k"
  timeout 120 feeddrive-sim "$s" --out "$out" -q || fail "feeddrive-sim failed on $s"
  pngs "$out/position.png" "$out/velocity_error.png" "$out/control.png" "$out/forces.png"
  no_mark "feeddrive-sim $s"
done
grep -q 'title "a?; system ?touch MARK?; print ?"' "$work/sim o'; touch MARK; echo '2/plots.gp" ||
  fail "the title is not the sanitised name"
pass "feeddrive-sim: scenario names, scenario file names and --out values ran nothing"

for s in "$work/named.yaml" "$work/a'; system 'touch MARK'; print '.yaml"; do
  out="$work/mp o'; touch MARK; echo '"
  timeout 120 feeddrive-launch "$s" --out "$out" -q --lcm-url "$URL" || fail "feeddrive-launch failed on $s"
  pngs "$out/position.png" "$out/velocity_error.png" "$out/control.png" "$out/forces.png"
  [ "$(json "$out/summary.json" .lockstep.completed)" = true ] || fail "launch: run not completed"
  no_mark "feeddrive-launch $s"
done
pass "feeddrive-launch (monitor): scenario names and file names ran nothing"

# feeddrive-fit: model, data and output named to run a command, the position column too; with plots.
sed -e 's/^duration: 10.0/duration: 3.0/' -e "s|file: rich_reference.csv|file: $SRC/scenarios/fit/rich_reference.csv|" \
  "$SRC/scenarios/fit/model.yaml" > "$work/m'; system 'touch MARK'; print '.yaml"
sed '/^  sensor:/a\  effects:\n    constant_force: {force: 15.0}' "$work/m'; system 'touch MARK'; print '.yaml" > "$work/truth.yaml"
grep -q constant_force "$work/truth.yaml" || fail "test setup: no effect in truth.yaml"
sim_run "$work/truth.yaml" "$work/truth"
col="pos'; system 'touch MARK'; print '"
sed "1s/x_measured/$col/" "$work/truth/timeseries.csv" > "$work/d'; system 'touch MARK'; print '.csv"
fit_out="$work/fit o'; touch MARK; echo '"
timeout 300 feeddrive-fit --scenario "$work/m'; system 'touch MARK'; print '.yaml" \
  --data "$work/d'; system 'touch MARK'; print '.csv" --position-column "$col" --out "$fit_out" --max-effects 1 -q \
  > /dev/null || [ $? = 3 ] || fail "feeddrive-fit failed"  # 3: an unexplained verdict, a result
pngs "$fit_out/replay.png" "$fit_out/gap.png" "$fit_out/effect1.png"
no_mark "feeddrive-fit"
pass "feeddrive-fit: model, data, column and --out names ran nothing"

# ---- 2. --out prev/ replaces an earlier output; anything else is refused untouched
timeout 120 feeddrive-launch "$scen" --out "$work/prev" -q --lcm-url "$URL" || fail "launch into prev"
[ -f "$work/prev/.feeddrive-output" ] || fail "no marker in prev"
[ -f "$work/prev/position.png" ] || fail "no plots in prev"
# A file of the user's inside the earlier output: refused before any process starts, kept.
echo mine > "$work/prev/notes.txt"
rc=0
timeout 120 feeddrive-launch "$scen" --out "$work/prev/" --no-plots -q --lcm-url "$URL" 2> "$TMP/notes.err" || rc=$?
[ "$rc" = 2 ] || fail "launch into prev/ holding notes.txt exited $rc, expected 2"
[ "$(grep -c "" "$TMP/notes.err")" = 1 ] && grep -q "holds 'notes.txt', which feeddrive did not write" "$TMP/notes.err" ||
  fail "launch into prev/ holding notes.txt: $(cat "$TMP/notes.err")"
[ "$(cat "$work/prev/notes.txt")" = mine ] || fail "notes.txt was touched"
pass "feeddrive-launch --out prev/ holding a file of the user's: $(cat "$TMP/notes.err")"
rm "$work/prev/notes.txt"
timeout 120 feeddrive-launch "$scen" --out "$work/prev/" --no-plots -q --lcm-url "$URL" || fail "launch into prev/"
[ -f "$work/prev/timeseries.csv" ] || fail "prev/ lost its results"
[ ! -e "$work/prev/position.png" ] || fail "prev/ was not replaced whole (the earlier plots remain)"
[ -z "$(find "$work" -maxdepth 1 -name '.prev.*')" ] || fail "temporary folders left: $(ls -a "$work")"
pass "feeddrive-launch --out prev/: the earlier output replaced in place"

mkdir -p "$work/user"
echo "keep me" > "$work/user/thesis.tex"
echo "not json" > "$work/user/summary.json"
for v in "$work/user" "$work/user/"; do
  set +e
  timeout 60 feeddrive-launch "$scen" --out "$v" -q --lcm-url "$URL" 2> "$TMP/err.txt"
  rc=$?
  set -e
  [ "$rc" = 2 ] || fail "launch --out $v: exit $rc, expected 2"
  [ "$(wc -l < "$TMP/err.txt")" = 1 ] || fail "launch --out $v: not one line: $(cat "$TMP/err.txt")"
  grep -q "^error: --out $v: .*not a feeddrive output" "$TMP/err.txt" || fail "message: $(cat "$TMP/err.txt")"
done
[ "$(ls -A "$work/user" | tr '\n' ' ')" = "summary.json thesis.tex " ] || fail "user folder changed: $(ls -A "$work/user")"
[ "$(cat "$work/user/thesis.tex")" = "keep me" ] || fail "thesis.tex changed"
for v in "" / . "$work/user/thesis.tex/out"; do
  set +e
  timeout 60 feeddrive-launch "$scen" --out "$v" -q --lcm-url "$URL" 2> "$TMP/err.txt"
  rc=$?
  set -e
  [ "$rc" = 2 ] || fail "launch --out '$v': exit $rc, expected 2"
  [ "$(wc -l < "$TMP/err.txt")" = 1 ] || fail "launch --out '$v': not one line: $(cat "$TMP/err.txt")"
  grep -q "^error: --out " "$TMP/err.txt" || fail "message: $(cat "$TMP/err.txt")"
done
pass "feeddrive-launch: a folder with a fake summary.json and unwritable --out values refused with exit 2, one line, untouched"

# ---- 3. the monitor cannot write (the file-size limit, ulimit -f, stops timeseries.csv at 100 KB of its ~240 KB):
# launch fails, the earlier output survives
before=$(md5sum < "$work/prev/timeseries.csv")
set +e
(ulimit -f 100; timeout 120 feeddrive-launch "$scen" --out "$work/prev" -q --lcm-url "$URL" 2> "$TMP/err.txt")
rc=$?
set -e
[ "$rc" != 0 ] || fail "feeddrive-launch exited 0 although its monitor could not write"
grep -q "File too large" "$TMP/err.txt" || fail "the monitor's error is not reported: $(cat "$TMP/err.txt")"
[ "$(md5sum < "$work/prev/timeseries.csv")" = "$before" ] || fail "the earlier output changed"
[ -f "$work/prev/.feeddrive-output" ] || fail "the earlier output lost its marker"
[ -z "$(find "$work" -maxdepth 1 -name '.prev.*')" ] || fail "temporary folders left: $(ls -a "$work")"
# and into a new folder: non-zero, no folder
set +e
(ulimit -f 100; timeout 120 feeddrive-launch "$scen" --out "$work/fresh" -q --lcm-url "$URL" 2> "$TMP/err.txt")
rc=$?
set -e
[ "$rc" != 0 ] || fail "feeddrive-launch exited 0 with no output folder"
[ ! -e "$work/fresh" ] || fail "a half-written folder"
pass "feeddrive-launch exits $rc when the monitor cannot write; the earlier output is intact"

# ---- 3b. gnuplot fails: the plots are a view of the data, which are written all the same
mkdir -p "$TMP/fakebin"
printf '#!/bin/sh\necho "fake gnuplot: cannot plot" >&2\nexit 1\n' > "$TMP/fakebin/gnuplot"
chmod +x "$TMP/fakebin/gnuplot"
PATH="$TMP/fakebin:$PATH" timeout 120 feeddrive-launch "$scen" --out "$work/noplots" -q --lcm-url "$URL" 2> "$TMP/err.txt" ||
  fail "feeddrive-launch failed because gnuplot did: $(cat "$TMP/err.txt")"
grep -q "plots not drawn (.*fake gnuplot" "$TMP/err.txt" || fail "no warning about the plots: $(cat "$TMP/err.txt")"
[ "$(json "$work/noplots/summary.json" .lockstep.completed)" = true ] || fail "noplots: not completed"
[ "$(($(wc -l < "$work/noplots/timeseries.csv") - 1))" = "$(json "$work/noplots/summary.json" .steps)" ] ||
  fail "noplots: timeseries.csv does not hold every step"
pass "a failing gnuplot costs the plots only: the record is complete and a warning says why"
