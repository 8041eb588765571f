#!/usr/bin/env bash
# One plugin, three hosts (docs/plugins.md): `cmake --install` of this build into a temporary
# prefix; the out-of-tree example examples/plugin (the boundary-layer sliding-mode law in C,
# find_package(feeddrive), only the ABI header) configured and built against that prefix alone;
# then its results against the built-in sliding_mode law on the paper's jerk-limited move:
#   1. feeddrive-sim:  the same timeseries.csv, byte for byte;
#   2. feeddrive-study: a small study (nominal + mass +-20 %, 4 threads) with both controllers:
#      every metric of every case the same;
#   3. over LCM: feeddrive-launch with the plugin scenario (the controller process hosts it), and
#      feeddrive-controller --plugin PATH as the external controller of the built-in scenario's run:
#      both the same timeseries.csv as feeddrive-sim's built-in run.
# And the one-line errors with exit 2 of the tools: a missing library, a missing symbol, an ABI
# mismatch, a plugin that returns NaN, one that throws.
source "$(dirname "$0")/lib.sh" "$@"
SDK=$TMP/sdk
cmake --install "$BUILD" --prefix "$SDK/prefix" > "$SDK.install.log" 2>&1 || { cat "$SDK.install.log" >&2; fail "cmake --install failed"; }
[ -f "$SDK/prefix/include/feeddrive/controller/plugin.h" ] || fail "plugin.h not installed"
cmake -S "$SRC/examples/plugin" -B "$SDK/plugin" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$SDK/prefix" \
  > "$SDK.configure.log" 2>&1 || { cat "$SDK.configure.log" >&2; fail "find_package(feeddrive) failed for examples/plugin"; }
cmake --build "$SDK/plugin" > "$SDK.build.log" 2>&1 || { tail -30 "$SDK.build.log" >&2; fail "examples/plugin does not build against the SDK"; }
LIB=$SDK/plugin/libfeeddrive_smc_bl.so
[ -f "$LIB" ] || fail "no $LIB"
# The plugin needs nothing of feeddrive at run time: libc and libm only.
ldd "$LIB" | grep -qi feeddrive && fail "the plugin links a feeddrive library: $(ldd "$LIB" | grep -i feeddrive)"
pass "examples/plugin built out of tree with find_package(feeddrive)"

BUILTIN=$SRC/scenarios/paper/smc_bl_jerk_limited.yaml
PLUGIN=$TMP/plugin.yaml
sed "s#library: build/libfeeddrive_smc_bl.so#library: $LIB#" "$SRC/examples/plugin/smc_bl_jerk_limited.yaml" > "$PLUGIN"
grep -q "library: $LIB" "$PLUGIN" || fail "the example scenario has no library line to point at the build"

# 1. feeddrive-sim
sim_run "$BUILTIN" "$TMP/sim_builtin"
sim_run "$PLUGIN" "$TMP/sim_plugin"
same_csv "$TMP/sim_builtin/timeseries.csv" "$TMP/sim_plugin/timeseries.csv"
e=$(json "$TMP/sim_plugin/summary.json" .position_error_max_abs_m)
pass "feeddrive-sim: the plugin's 15000 rows identical to the built-in law's (max |e| = $e m)"

# 2. feeddrive-study: both controllers, the same cases.
cat > "$TMP/study.yaml" << YAML
name: plugin_vs_builtin
base: $BUILTIN
set: {duration: 0.6}
controllers:
  - {name: builtin, scenario: $BUILTIN}
  - name: plugin
    controller:
      type: plugin
      library: $LIB
      parameters: {eta: 5.0, k: 10.0, lambda: 50.0, switching: sat, boundary_layer: 5.0e-4}
families:
  - name: nominal
  - name: mass
    grid: [{key: plant.mass, scale: [0.8, 1.2]}]
  - name: friction
    grid: [{keys: [plant.friction.static_force, plant.friction.coulomb_force], scale: [0.7, 1.3]}]
YAML
timeout 600 feeddrive-study "$TMP/study.yaml" --out "$TMP/study" -j 4 --no-plots -q || fail "feeddrive-study failed"
python3 - "$TMP/study/results.csv" << 'PY' || fail "study: the plugin's results differ from the built-in law's"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
by = {}
for r in rows:
    by.setdefault(r["controller"], []).append(r)
b, p = by["builtin"], by["plugin"]
assert len(b) == len(p) == 5, (len(b), len(p))
skip = {"case", "controller", "hash"}
for rb, rp in zip(b, p):
    assert rb["ok"] == rp["ok"] == "true", (rb["ok"], rp["ok"], rp.get("error"))
    for k in rb:
        if k not in skip and rb[k] != rp[k]:
            sys.exit(f"case {rb['family']}/{rb['point']}: {k} = {rb[k]} (builtin) vs {rp[k]} (plugin)")
print(f"study: {len(p)} cases per controller, every column equal")
PY
pass "feeddrive-study: 5 cases (nominal, mass +-20 %, Fs/Fc +-30 %), plugin = built-in in every metric"
# A rerun into the same folder keeps every finished case; after the plugin's library changes (the
# same path, other bytes: a rebuild), the plugin's cases run again and the built-in law's do not.
timeout 600 feeddrive-study "$TMP/study.yaml" --out "$TMP/study" -j 4 --no-plots -q || fail "study rerun failed"
[ "$(json "$TMP/study/timing.json" .cases_run)" = 0 ] || fail "rerun: $(json "$TMP/study/timing.json" .cases_run) cases run again"
printf 'rebuilt' >> "$LIB"  # trailing bytes: still a loadable library, another digest
timeout 600 feeddrive-study "$TMP/study.yaml" --out "$TMP/study" -j 4 --no-plots -q || fail "study rerun after the rebuild failed"
[ "$(json "$TMP/study/timing.json" .cases_run)" = 5 ] && [ "$(json "$TMP/study/timing.json" .cases_reused)" = 5 ] ||
  fail "after the plugin changed: $(json "$TMP/study/timing.json" .cases_run) cases run, $(json "$TMP/study/timing.json" .cases_reused) reused (want 5 and 5)"
pass "feeddrive-study rerun: nothing run again; after the plugin library changed, its 5 cases run again"

# 3. over LCM: the plugin scenario through feeddrive-launch (feeddrive-controller loads it) ...
timeout 300 feeddrive-launch "$PLUGIN" --out "$TMP/mp_plugin" --no-plots -q --lcm-url "$URL"
[ "$(json "$TMP/mp_plugin/summary.json" .lockstep.completed)" = true ] || fail "launch: not completed"
same_csv "$TMP/sim_builtin/timeseries.csv" "$TMP/mp_plugin/timeseries.csv"
# ... and feeddrive-controller --plugin as the external controller of the built-in scenario's run:
# the plugin scenario gives the parameters, --plugin the library (a copy, so it is that one).
cp "$LIB" "$TMP/copy.so"
timeout 300 feeddrive-controller "$PLUGIN" --plugin "$TMP/copy.so" --lcm-url "$URL" 2> "$TMP/c.err" & c=$!
timeout 300 feeddrive-launch "$BUILTIN" --out "$TMP/mp_ext" --no-plots -q --external controller --lcm-url "$URL"
wait $c || { cat "$TMP/c.err" >&2; fail "feeddrive-controller --plugin failed"; }
same_csv "$TMP/sim_builtin/timeseries.csv" "$TMP/mp_ext/timeseries.csv"
pass "over LCM: feeddrive-launch of the plugin scenario and feeddrive-controller --plugin: rows identical to feeddrive-sim's built-in run"

# Errors: one line, exit 2, naming the library and the cause.
PD=$BUILD/tests/plugins
expect_error() {  # LIBRARY EXPECTED-TEXT [TOOL...]
  local lib=$1 want=$2 rc=0
  # The plugin scenario without its parameters (the test plugins take only `gain`).
  sed "s#library: .*#library: $lib#" "$PLUGIN" | awk '/^  parameters:/ { skip = 1; next } skip && /^    / { next } { skip = 0; print }' > "$TMP/bad.yaml"
  feeddrive-sim "$TMP/bad.yaml" --out "$TMP/bad_out" --no-plots -q 2> "$TMP/err" || rc=$?
  [ "$rc" = 2 ] || { cat "$TMP/err" >&2; fail "$lib: exit $rc, not 2"; }
  [ "$(wc -l < "$TMP/err")" = 1 ] || { cat "$TMP/err" >&2; fail "$lib: not one line"; }
  grep -qF "$want" "$TMP/err" || { cat "$TMP/err" >&2; fail "$lib: the message does not say '$want'"; }
  [ -e "$TMP/bad_out" ] && fail "$lib: an output folder was left"
  echo "  $(cat "$TMP/err")"
}
expect_error "$TMP/nowhere.so" "no such file"
expect_error "$PD/libfd_fault_no_reset.so" "missing symbol feeddrive_controller_reset"
expect_error "$PD/libfd_fault_version.so" "ABI version 999, this feeddrive hosts ABI version 2"
# A plugin built for ABI version 1 (the model as a struct of fields, before issue 22's table).
expect_error "$PD/libfd_fault_old.so" "ABI version 1, this feeddrive hosts ABI version 2 only (rebuild the plugin"
expect_error "$PD/libfd_fault_nan.so" "returned u = nan"
expect_error "$PD/libfd_fault_throw.so" "an exception left the plugin"
rc=0
timeout 60 feeddrive-controller "$BUILTIN" --plugin "$PD/libfd_fault_version.so" --lcm-url "$URL" 2> "$TMP/err" || rc=$?
[ "$rc" = 2 ] && grep -q "ABI version 999" "$TMP/err" || { cat "$TMP/err" >&2; fail "feeddrive-controller --plugin (ABI 999): exit $rc"; }
pass "errors: missing library, missing symbol, ABI mismatch (999, and an ABI 1 plugin), NaN, exception: one line and exit 2 each"
