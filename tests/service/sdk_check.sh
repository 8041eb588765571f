#!/usr/bin/env bash
# sdk_check TREE: the SDK checks of sdk_test.sh and sdk_shared_test.sh on the build tree TREE
# (sourced after lib.sh): `cmake --install TREE` into a temporary prefix, the out-of-tree example
# examples/cpp (find_package(feeddrive), the project's sliding-mode law over LCM) configured and
# built against that prefix alone, linked without CVODE, then run as the controller of the paper's
# jerk-limited move with feeddrive-launch --external controller, configuring itself from run_info_t.
sdk_check() {
  local BUILD=$1 TMP=$TMP/sdk-$(basename "$1")
  mkdir -p "$TMP"
  cmake --install "$BUILD" --prefix "$TMP/prefix" > "$TMP/install.log" || { cat "$TMP/install.log" >&2; fail "cmake --install failed"; }
  for f in lib/cmake/feeddrive/feeddriveConfig.cmake include/feeddrive/controller/sliding_mode.hpp \
           include/feeddrive/run_info_t.hpp include/feeddrive/plant/forces.hpp; do
    [ -f "$TMP/prefix/$f" ] || fail "not installed: $f"
  done
  ls "$TMP"/prefix/lib/libfeeddrive_controller.* > /dev/null || fail "no controller library installed"
  cmake -S "$SRC/examples/cpp" -B "$TMP/example" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$TMP/prefix" \
    > "$TMP/configure.log" 2>&1 || { cat "$TMP/configure.log" >&2; fail "find_package(feeddrive) failed"; }
  cmake --build "$TMP/example" > "$TMP/build.log" 2>&1 || { tail -30 "$TMP/build.log" >&2; fail "the example does not build against the SDK"; }
  exe=$TMP/example/sliding-mode-controller
  # No CVODE in the controller: neither linked (shared builds) nor compiled in (static ones).
  ldd "$exe" | grep -qi sundials && fail "the example links SUNDIALS: $(ldd "$exe" | grep -i sundials)"
  nm -C "$exe" | grep -qi cvode && fail "the example contains CVODE code"
  scen=$SRC/scenarios/paper/smc_bl_jerk_limited.yaml
  timeout 120 "$exe" "$URL" FD 2> "$TMP/c.err" & c=$!
  timeout 120 feeddrive-launch "$scen" --out "$TMP/run" --no-plots -q --external controller --lcm-url "$URL"
  wait $c || { cat "$TMP/c.err" >&2; fail "the example controller failed"; }
  # Its whole model from run_info_t.plant (contract 4), delta included.
  grep -q "run smc_bl_jerk_limited (lockstep): T = 0.0001 s, 15000 steps, m = 102.04 kg, Ka\*Kf = 260 N/V, friction lugre (Fs 120 N, Fc 80 N, vs 0.1 m/s, delta 2)" "$TMP/c.err" ||
    { cat "$TMP/c.err" >&2; fail "the example did not configure itself from run_info_t"; }
  [ "$(json "$TMP/run/summary.json" .lockstep.completed)" = true ] || fail "run not completed"
  e=$(json "$TMP/run/summary.json" .position_error_max_abs_m)
  # The paper's law with the bristle and grinding observers (no truth) on the ideal-encoder move:
  # 3.6 nm measured; 20 nm leaves room and still fails on a wrong model (the law without its
  # friction compensation leaves micrometres, see the C sketch's 2.3 um).
  awk -v e="$e" 'BEGIN { exit !(e < 2e-8) }' || fail "max |e| = $e m"
  pass "SDK: installed, example built with find_package(feeddrive) without CVODE, run completed, max |e| = $e m"
}
