# Shared helpers of the multi-process tests. Each test runs inside its own network namespace
# (scripts/netns-run.sh, from ctest), so tests in parallel never hear each other.
# Usage in a test:  source "$(dirname "$0")/lib.sh" "$@"   (arguments: SOURCE_DIR BUILD_DIR)
set -euo pipefail
SRC=$(cd "$1" && pwd)
BUILD=$(cd "$2" && pwd)
BIN=$BUILD/bin
URL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304'
# Outside a private namespace (netns-run.sh fell back to the host, or the test was started by
# hand) tests running in parallel would hear each other: give each its own port.
if [ "${FEEDDRIVE_NETNS:-}" != private ]; then
  URL="udpm://239.255.76.67:$((20000 + $$ % 20000))?ttl=0&recv_buf_size=4194304"
  echo "note: no private network namespace (FEEDDRIVE_NETNS=${FEEDDRIVE_NETNS:-unset}): host loopback, ttl=0, $URL"
fi
# skip REASON: the test cannot run here; says why and passes (ctest has no skip code for it).
skip() { echo "SKIPPED: $*"; exit 0; }
TMP=$(mktemp -d "${TMPDIR:-/tmp}/feeddrive-test.XXXXXX")
# Where lcm-logger writes: memory (tmpfs) where there is one. The stock logger drops messages
# once 30 are queued, so a write that waits on a busy disk for a few milliseconds (other tests
# writing their results) would cost it steps.
LOGDIR=$TMP
if [ -d /dev/shm ] && [ -w /dev/shm ]; then LOGDIR=$(mktemp -d /dev/shm/feeddrive-log.XXXXXX); fi
trap 'jobs -p | xargs -r kill -9 2>/dev/null || true; [ -n "${FD_KEEP_TMP:-}" ] || rm -rf "$TMP" "$LOGDIR"' EXIT
export PATH="$BIN:$PATH"

fail() { echo "FAIL: $*" >&2; exit 1; }
pass() { echo "PASS: $*"; }
# wait_until SECONDS WHAT COMMAND...: runs COMMAND every 50 ms until it succeeds; fails naming
# WHAT after SECONDS. The wait on a condition with a deadline that replaces a fixed sleep: a
# sleep long enough on a loaded machine wastes time on every other, and one short enough here
# fails there.
wait_until() {
  local seconds=$1 what=$2 i
  shift 2
  for ((i = 0; i < seconds * 20; i++)); do
    "$@" && return 0
    sleep 0.05
  done
  fail "$what: not within $seconds s"
}
# monitor_step FILE: the step of the monitor's last progress line ("[monitor] step N/M ...", every
# 0.5 s, not with -q) in FILE, a stderr the monitor or feeddrive-launch writes; 0 before the first.
monitor_step() {
  local at
  at=$(tr '\r' '\n' < "$1" 2> /dev/null | grep -o "step [0-9]*" | tail -n 1 | cut -d' ' -f2 || true)
  echo "${at:-0}"
}
# monitor_step_at_least FILE STEP: the monitor's progress line in FILE says STEP or later.
monitor_step_at_least() { [ "$(monitor_step "$1")" -ge "$2" ]; }
# wait_step FILE STEP: waits until the monitor's progress line in FILE says step STEP or later,
# within 30 s: the point of a fault injection is a step of the run, not a time, so it falls
# mid-run on a machine of any speed. Fails naming FILE and STEP.
wait_step() {
  wait_until 30 "the monitor's progress in $1 reached step $2" monitor_step_at_least "$1" "$2"
}
# wait_bus_step STEP [PREFIX]: waits until a state of step STEP or later is on the bus (the run
# is that far; fd-test-peer watch listens, never publishes), within 30 s; fails naming STEP. For
# a run started with -q, whose stderr has no progress line for wait_step to read.
wait_bus_step() {
  "$BUILD/tests/fd-test-peer" watch --steps "$1" --prefix "${2:-FD}" --lcm-url "$URL" --seconds 30 > /dev/null ||
    fail "no state of step $1 or later on the bus within 30 s"
}
# cpu_ms_at_least PID MS: process PID (all its threads) has used at least MS ms of CPU time
# (user + system, /proc/PID/stat): how far a computation has come, whatever the machine's load.
cpu_ms_at_least() {
  local stat ticks
  stat=$(cat "/proc/$1/stat" 2> /dev/null) || return 1
  ticks=$(echo "${stat##*) }" | awk '{ print $12 + $13 }')  # utime, stime: fields 14, 15 of the line
  [ $((ticks * 1000 / $(getconf CLK_TCK))) -ge "$2" ]
}
# descendants PID: the processes below PID (its children, theirs, ...).
descendants() {
  local c
  for c in $(pgrep -P "$1" || true); do echo "$c"; descendants "$c"; done
}
# on_bus PORT PID [NAME]: PID or a process below it (timeout, chrt, feeddrive-launch's children),
# named NAME if given, has a UDP socket on PORT.
on_bus() {
  local pid
  for pid in $2 $(descendants "$2"); do
    [ -z "${3:-}" ] || [ "$(cat "/proc/$pid/comm" 2>/dev/null)" = "${3:0:15}" ] || continue  # comm: 15 characters
    ss -Huanp "sport = :$1" 2>/dev/null | grep -q "pid=$pid," && return 0
  done
  return 1
}
# wait_on_bus PID [NAME]: waits until process PID or a process below it (named NAME if given:
# feeddrive-launch's feeddrive-monitor) has a UDP socket on the URL's port, i.e. has joined the
# LCM bus, so it cannot miss the start of what follows. Fails after 10 s.
wait_on_bus() {
  local port=${URL#udpm://*:}
  port=${port%%\?*}
  wait_until 10 "${2:-process} $1 joined the LCM bus on port $port" on_bus "$port" "$1" "${2:-}"
}
# stop_logger PID FILE PREFIX: ends the stock lcm-logger PID (recording PREFIX_.* into FILE) once
# FILE holds the run's last message, PREFIX_SUMMARY (the monitor sends it after every step is
# in: a logger that wrote it has every message before it). The logger writes through a buffer
# that it flushes only when an event comes and --flush-interval (100 ms) has passed, and it does
# not drain its socket on SIGINT: after the run nothing would flush its tail. So fd-test-peer
# mark sends a 5-byte marker on PREFIX_TEST_FLUSH every 20 ms (no part of the contract:
# feeddrive-log2csv and feeddrive-fit count it among the foreign events), and the wait is on the
# summary's channel name in FILE, within 10 s. Then SIGINT; the markers end first.
stop_logger() {
  local lg=$1 file=$2 prefix=$3 mk
  "$BUILD/tests/fd-test-peer" mark --lcm-url "$URL" --prefix "$prefix" --seconds 30 > /dev/null & mk=$!
  wait_until 10 "lcm-logger wrote ${prefix}_SUMMARY, the run's last message, to $file" \
    grep -qaF "${prefix}_SUMMARY" "$file"
  kill "$mk" 2> /dev/null || true
  wait "$mk" 2> /dev/null || true
  kill -INT "$lg"
  wait "$lg" || true
}
# json FILE JQ-FILTER
json() { jq -r "$2" "$1"; }
# jerk_move FILE SECONDS: the paper's jerk-limited move (scenarios/paper/smc_bl_jerk_limited.yaml)
# with its duration set to SECONDS, written to FILE; fails the test if no duration line was set.
jerk_move() {
  sed "s/^duration: .*/duration: $2/" "$SRC/scenarios/paper/smc_bl_jerk_limited.yaml" > "$1"
  grep -q "^duration: $2\$" "$1" || fail "could not set the duration of $1 to $2"
}
# Runs feeddrive-sim on a scenario into DIR (the in-process reference result).
sim_run() { timeout 300 feeddrive-sim "$1" --out "$2" --no-plots --quiet; }
# Same bytes or fail, naming the first differing line.
same_csv() {
  if ! cmp -s "$1" "$2"; then
    diff <(head -c 2000000 "$1") <(head -c 2000000 "$2") | head -5 >&2 || true
    fail "$1 and $2 differ"
  fi
}
