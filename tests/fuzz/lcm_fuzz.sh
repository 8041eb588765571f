#!/usr/bin/env bash
# The LCM-log part of the fuzz suite (tests/fuzz/fuzz.py, mode lcm): records a four-process run
# with the stock lcm-logger (1.5 s of the docs/fit.md drive at 1 kHz with a hidden constant
# force), checks that the unmutated log converts and fits, then runs the seeded mutations.
# Arguments: SOURCE_DIR BUILD_DIR FIRST_SEED CASES.
source "$(dirname "$0")/../service/lib.sh" "$1" "$2"
seed=$3
cases=$4
ref=$SRC/scenarios/fit/rich_reference.csv
sed -e 's/^duration: 10\.0/duration: 1.5/' -e "s#file: rich_reference.csv#file: $ref#" \
  -e 's/^controller:/  effects:\n    constant_force: {force: 15.0}\ncontroller:/' \
  "$SRC/scenarios/fit/model.yaml" > "$TMP/truth.yaml"
grep -q 'constant_force' "$TMP/truth.yaml" || fail "truth.yaml: effect not added"
prio=(chrt -f 20)
"${prio[@]}" true 2>/dev/null || prio=()
"${prio[@]}" timeout 300 lcm-logger --lcm-url="$URL" --channel='FD_.*' --force "$LOGDIR/run.lcmlog" 2> "$TMP/logger.err" & lg=$!
wait_on_bus $lg
timeout 300 feeddrive-launch "$TMP/truth.yaml" --out "$TMP/mon" --no-plots -q --lcm-url "$URL"
stop_logger $lg "$LOGDIR/run.lcmlog" FD  # once it has the whole run (lib.sh)
[ -s "$LOGDIR/run.lcmlog" ] || fail "lcm-logger wrote no log"
# The unmutated log: complete, and fitted (the base line every mutation is measured against).
timeout 120 feeddrive-log2csv "$LOGDIR/run.lcmlog" --scenario "$TMP/truth.yaml" --out "$TMP/conv" -q
[ "$(json "$TMP/conv/summary.json" .log.missing_steps)" = 0 ] || fail "the unmutated log has gaps (lcm-logger dropped messages)"
pass "base log: $(stat -c %s "$LOGDIR/run.lcmlog") bytes, $(json "$TMP/conv/summary.json" .steps) steps"
python3 "$SRC/tests/fuzz/fuzz.py" lcm --src "$SRC" --bin "$BIN" --seed "$seed" --cases "$cases" --jobs 2 \
  --log "$LOGDIR/run.lcmlog" --scenario "$TMP/truth.yaml" --work "$TMP/cases"
