#!/usr/bin/env bash
# End-to-end test of the Lua example controller (examples/lua/controller.lua) as the external
# controller of a lockstep run of the paper's jerk-limited move:
#   feeddrive-launch scenarios/paper/smc_bl_jerk_limited.yaml --external controller   (background)
#   lua5.2 examples/lua/controller.lua                                               (background)
# Twice: unsigned, then with --key (both sign every message; the Lua side with luaossl).
# Both must exit 0 each time, and summary.json must show 15000 steps, lockstep.completed = true, no invalid
# messages, no rejected commands, and max |xd - x| below MAX_ERROR_M.
#
# Usage: lua_controller_test.sh SOURCE_DIR BUILD_DIR
# Run it inside a private network namespace (ctest does: scripts/netns-run.sh bash THIS SRC BUILD);
# this script does not create one. Every process runs under `timeout`, so it never hangs.
set -euo pipefail

if [ "$#" -ne 2 ]; then
  echo "usage: $0 SOURCE_DIR BUILD_DIR" >&2
  exit 2
fi
SRC=$(cd "$1" && pwd)
BUILD=$(cd "$2" && pwd)

# Bound on max |xd - x| [m]. The law leaves |e| <= F_missed / (m*(eta/phi + k)*lambda)
# = 120 N / (1.02e6 N s/m * 50 1/s) = 2.4 um even without its integral term (the worst friction
# the static feed-forward misses is the 120 N breakaway); with the default ki = 1e6 it measures
# 0.32 um. 5 um is twice the analytic no-integral bound: it passes with margin on any machine
# (in lockstep the timing does not change the numbers) and fails if the law, the units or the
# step protocol break (an unanswered, recomputed or mis-numbered step shows as tens of um).
MAX_ERROR_M=5e-6
STEPS=15000
PROCESS_TIMEOUT=120

SCENARIO="$SRC/scenarios/paper/smc_bl_jerk_limited.yaml"
LAUNCH="$BUILD/bin/feeddrive-launch"
CONTROLLER="$SRC/examples/lua/controller.lua"
LUA_TYPES="$BUILD/lcmtypes/lua"

fail() { echo "lua_controller_test: FAIL: $*" >&2; exit 1; }

command -v lua5.2 >/dev/null || fail "lua5.2 not found (scripts/install-deps.sh installs lua5.2 and liblcm-lua)"
command -v jq >/dev/null || fail "jq not found (scripts/install-deps.sh installs it)"
[ -x "$LAUNCH" ] || fail "$LAUNCH not built"
[ -f "$LUA_TYPES/feeddrive/init.lua" ] || fail "$LUA_TYPES/feeddrive/init.lua missing (lcm-gen --lua runs at build time)"
[ -f "$CONTROLLER" ] || fail "$CONTROLLER missing"
lua5.2 -e 'require("lcm")' || fail "the Lua LCM module does not load (Debian package liblcm-lua)"

TMP=$(mktemp -d)
LAUNCH_PID=""
CONTROLLER_PID=""
cleanup() {
  for pid in $LAUNCH_PID $CONTROLLER_PID; do kill "$pid" 2>/dev/null || true; done
  rm -rf "$TMP"
}
trap cleanup EXIT

# A prefix of our own: harmless in a private namespace, and keeps parallel runs apart if
# netns-run.sh had to fall back to the host loopback.
PREFIX="FDLUA$$"
export LUA_PATH="$LUA_TYPES/?.lua;$LUA_TYPES/?/init.lua;;"

cd "$SRC"

# run_case NAME [ARGS...]: one run with the Lua controller; ARGS go to both processes.
run_case() {
  local name=$1
  shift
  OUT="$TMP/$name"
  timeout -k 5 "$PROCESS_TIMEOUT" "$LAUNCH" "$SCENARIO" --out "$OUT" --no-plots --external controller \
    --prefix "$PREFIX" --quiet "$@" >"$TMP/$name.launch.log" 2>&1 &
  LAUNCH_PID=$!
  timeout -k 5 "$PROCESS_TIMEOUT" lua5.2 "$CONTROLLER" --prefix "$PREFIX" "$@" >"$TMP/$name.controller.log" 2>&1 &
  CONTROLLER_PID=$!

  launch_rc=0
  wait "$LAUNCH_PID" || launch_rc=$?
  LAUNCH_PID=""
  controller_rc=0
  wait "$CONTROLLER_PID" || controller_rc=$?
  CONTROLLER_PID=""

  show_logs() {
    echo "--- $name: feeddrive-launch (exit $launch_rc) ---" >&2
    tail -n 30 "$TMP/$name.launch.log" >&2 || true
    echo "--- $name: controller.lua (exit $controller_rc) ---" >&2
    tail -n 30 "$TMP/$name.controller.log" >&2 || true
  }
  if [ "$launch_rc" -ne 0 ] || [ "$controller_rc" -ne 0 ]; then
    show_logs
    fail "$name: feeddrive-launch exited $launch_rc, controller.lua exited $controller_rc (124: timed out after ${PROCESS_TIMEOUT} s)"
  fi

  SUMMARY="$OUT/summary.json"
  [ -f "$SUMMARY" ] || { show_logs; fail "$name: $SUMMARY not written"; }

  check() {  # check DESCRIPTION JQ_FILTER: the filter must be true
    if ! jq -e --argjson max "$MAX_ERROR_M" --argjson steps "$STEPS" "$2" "$SUMMARY" >/dev/null; then
      show_logs
      jq '{steps, position_error_max_abs_m, lockstep}' "$SUMMARY" >&2 || true
      fail "$name: $1"
    fi
  }
  check "steps != $STEPS" '.steps == $steps'
  check "lockstep.completed != true" '.lockstep.completed == true'
  check "lockstep.stopped_at_step != $STEPS" '.lockstep.stopped_at_step == $steps'
  check "invalid messages on the bus" '.lockstep.invalid_messages == 0'
  check "foreign, conflicting or unauthenticated messages on the bus" \
    '.lockstep.foreign_messages == 0 and .lockstep.conflicts == 0 and .lockstep.unauthenticated_messages == 0'
  check "the plant rejected or clipped commands" '.lockstep.rejected_commands == 0'
  check "position_error_max_abs_m is not a number" '(.position_error_max_abs_m | type) == "number"'
  check "max |e| >= $MAX_ERROR_M m" '.position_error_max_abs_m < $max'

  jq -r '"lua_controller_test: PASS (\($name)): \(.steps) steps, max |e| = \(.position_error_max_abs_m) m (bound \($max)), " +
         "rms \(.position_error_rms_m) m, u in [\(.control_min), \(.control_max)] V, " +
         "resends \(.lockstep.resends), lost \(.lockstep.lost), authenticated \(.lockstep.authenticated), " +
         "state->command p50 \(.lockstep.latency_us.state_to_command.p50) us, wall \(.wall_time_s) s"' \
    --arg name "$name" --argjson max "$MAX_ERROR_M" "$SUMMARY"
}

run_case plain

# Signed (docs/security.md): the same run with every message authenticated by HMAC-SHA256; the
# Lua controller signs with luaossl (Debian lua-luaossl). Every message must pass (0 rejected),
# and the record must be the unsigned run's, byte for byte (lockstep: the key changes nothing
# but the wire).
lua5.2 -e 'require("openssl.hmac")' || fail "luaossl does not load (Debian package lua-luaossl)"
head -c 32 /dev/urandom > "$TMP/key"
chmod 600 "$TMP/key"
run_case signed --key "$TMP/key"
jq -e '.lockstep.authenticated == true' "$TMP/signed/summary.json" >/dev/null || fail "signed: lockstep.authenticated != true"
cmp -s "$TMP/plain/timeseries.csv" "$TMP/signed/timeseries.csv" || fail "signed: timeseries.csv differs from the unsigned run's"
echo "lua_controller_test: PASS: the signed run's timeseries.csv is the unsigned run's, byte for byte"
