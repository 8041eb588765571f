#!/usr/bin/env bash
# Lockstep speed against its ceiling, measured in the same run (run inside a private network
# namespace: scripts/netns-run.sh bench/lockstep_bench.sh [BUILD_DIR] [ROUNDS]):
#   1. the ceiling: a raw liblcm ping-pong between two processes (bench/lcm_pingpong_raw.c: only
#      lcm_publish and lcm_handle), one round trip per step;
#   2. the same ping-pong through the project's Bus (bench/lcm_pingpong.cpp: decoding, polling,
#      the direct socket the plant and the controller use);
#   3. the four-process lockstep run (plant + controller + trajectory + monitor) of the paper's
#      boundary-layer jerk-limited move, 15,000 steps; steps/s from the monitor (first to last step).
# Each is run ROUNDS times (default 5), alternating; medians and their ratios are printed, for
# two placements: free (the scheduler's) and one core (all processes pinned to CPU 0).
# Targets: lockstep >= 0.8 x raw; Bus ping-pong >= 0.95 x raw.
# Then recording: the same lockstep run alone, with the stock lcm-logger next to it (real-time
# priority where permitted, as docs/lcm-contract.md recommends) and with the monitor's own log
# (feeddrive-launch --lcm-log), alternating; medians of steps/s.
# Last, what other processes on the multicast group cost a ping-pong round trip (why the
# monitor and the trajectory read in batches; docs/lcm-contract.md, "Receiving").
# Then the cost of authentication (--key, HMAC-SHA256 on every message; docs/security.md): the
# same lockstep run without and with a key, alternating, medians, ratio and cost per step.
# A third argument "auth" runs only that part: bench/lockstep_bench.sh BUILD ROUNDS auth
# A third argument "speed" runs only the lockstep-against-raw part, on the paper's 50 kHz
# smc_jerk_limited (50,000 steps of 20 us) and on beyond_jerk_limited (15,000 of 100 us), both
# placements (issue 21, point 9): bench/lockstep_bench.sh BUILD ROUNDS speed
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
ROUNDS=${2:-5}
URL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304'
SCEN=scenarios/paper/smc_bl_jerk_limited.yaml
TMP=$(mktemp -d)
LOGDIR=$TMP
if [ -d /dev/shm ] && [ -w /dev/shm ]; then LOGDIR=$(mktemp -d /dev/shm/feeddrive-bench.XXXXXX); fi
trap 'jobs -p | xargs -r kill 2>/dev/null || true; rm -rf "$TMP" "$LOGDIR"' EXIT
median() { printf '%s\n' "$@" | sort -g | awk '{ a[NR] = $1 } END { print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.3f", a / b }'; }
steps_per_s() { jq -r .lockstep.steps_per_second "$1/summary.json"; }
# bench PLACEMENT: "free" (the scheduler places the processes) or "one-core" (every process
# pinned to CPU 0: taskset for the ping-pongs, feeddrive-launch --cpus 0).
bench() {
  local placement=$1 scen=${2:-$SCEN} pin=() cpus=() raw=() bus=() ls=() rate name
  name=$(basename "$scen" .yaml)
  if [ "$placement" = one-core ]; then pin=(taskset -c 0); cpus=(--cpus 0); fi
  for r in $(seq "$ROUNDS"); do
    "${pin[@]}" "$BUILD/bin/lcm-pingpong-raw" server "$URL" "RAW$placement$r" & srv=$!
    rate=$("${pin[@]}" "$BUILD/bin/lcm-pingpong-raw" client "$URL" "RAW$placement$r" 15000 | awk '/pingpong_rate/ { print $2 }')
    wait $srv; raw+=("$rate")
    "${pin[@]}" "$BUILD/bin/lcm-pingpong" server --lcm-url "$URL" --prefix "BUS$placement$r" & srv=$!
    rate=$("${pin[@]}" "$BUILD/bin/lcm-pingpong" client --count 15000 --lcm-url "$URL" --prefix "BUS$placement$r" |
           awk '/pingpong_rate/ { print $2 }')
    wait $srv; bus+=("$rate")
    "$BUILD/bin/feeddrive-launch" "$scen" --out "$TMP/run$placement$r" --no-plots -q \
        --lcm-url "$URL" --prefix "LS$placement$r" "${cpus[@]}"
    ls+=("$(steps_per_s "$TMP/run$placement$r")")
    echo "$name $placement round $r: raw liblcm ping-pong ${raw[-1]}, Bus ping-pong ${bus[-1]} round trips/s; lockstep ${ls[-1]} steps/s"
  done
  local mr mb ml
  mr=$(median "${raw[@]}"); mb=$(median "${bus[@]}"); ml=$(median "${ls[@]}")
  echo "$name $placement: medians: raw liblcm ping-pong $mr, Bus ping-pong $mb round trips/s; lockstep $ml steps/s (4 processes, CVODE plant, sliding-mode controller)"
  echo "$name $placement: Bus ping-pong / raw: $(ratio "$mb" "$mr") (target >= 0.95); lockstep / raw: $(ratio "$ml" "$mr") (target >= 0.8)"
  # The Bus ping-pong waits on its own socket (no liblcm receive thread, no pipe): where it beats
  # liblcm, it is the stronger baseline, so the lockstep run is also put against it.
  echo "$placement: lockstep / Bus ping-pong: $(ratio "$ml" "$mb") (a four-process CVODE step against a bare round trip on the same receive path)"
}
auth() {
  local plain=() keyed=() key="$TMP/bench.key"
  head -c 32 /dev/urandom > "$key"
  chmod 600 "$key"
  for r in $(seq "$ROUNDS"); do
    for mode in plain keyed; do
      local k=(); [ "$mode" = keyed ] && k=(--key "$key")
      "$BUILD/bin/feeddrive-launch" scenarios/paper/smc_bl_jerk_limited.yaml --out "$TMP/auth$mode$r" --no-plots -q \
          --lcm-url "$URL" --prefix "AU$mode$r" --cpus 0 "${k[@]}"
      local rate
      rate=$(jq -r .lockstep.steps_per_second "$TMP/auth$mode$r/summary.json")
      [ "$mode" = plain ] && plain+=("$rate") || keyed+=("$rate")
    done
    echo "auth round $r: without a key ${plain[-1]} steps/s, with --key ${keyed[-1]} steps/s"
  done
  local mp mk
  mp=$(median "${plain[@]}"); mk=$(median "${keyed[@]}")
  awk -v p="$mp" -v k="$mk" 'BEGIN { printf "auth (one core): median %s steps/s without a key, %s with --key: ratio %.3f, cost %.2f us per step (HMAC-SHA256 of every message sent and received)\n", p, k, k / p, 1e6 / k - 1e6 / p }'
}
if [ "${3:-all}" = speed ]; then
  for scen in scenarios/paper/smc_jerk_limited.yaml scenarios/paper/beyond_jerk_limited.yaml; do
    bench free "$scen"
    bench one-core "$scen"
  done
  exit 0
fi
if [ "${3:-all}" = auth ]; then
  auth
  exit 0
fi
bench free
bench one-core

# Recording: alone, with the stock lcm-logger, with the monitor's --lcm-log.
prio=(chrt -f 20)
"${prio[@]}" true 2>/dev/null || { echo "note: no real-time priority for lcm-logger here; it runs at normal priority"; prio=(); }
alone=(); stock=(); own=()
for r in $(seq "$ROUNDS"); do
  "$BUILD/bin/feeddrive-launch" "$SCEN" --out "$TMP/alone$r" --no-plots -q --lcm-url "$URL" --prefix "LA$r"
  alone+=("$(steps_per_s "$TMP/alone$r")")
  "${prio[@]}" lcm-logger --lcm-url="$URL" --channel="LL${r}_.*" --force "$LOGDIR/stock$r.lcmlog" > /dev/null 2>&1 & lg=$!
  sleep 0.5   # the logger joins the group
  "$BUILD/bin/feeddrive-launch" "$SCEN" --out "$TMP/stock$r" --no-plots -q --lcm-url "$URL" --prefix "LL$r"
  kill -INT $lg; wait $lg || true
  stock+=("$(steps_per_s "$TMP/stock$r")")
  "$BUILD/bin/feeddrive-launch" "$SCEN" --out "$TMP/own$r" --no-plots -q --lcm-url "$URL" --prefix "LO$r" \
      --lcm-log "$LOGDIR/own$r.lcmlog"
  own+=("$(steps_per_s "$TMP/own$r")")
  complete=$("$BUILD/bin/feeddrive-log2csv" "$LOGDIR/stock$r.lcmlog" --prefix "LL$r" --scenario "$SCEN" --out "$TMP/conv$r" -q 2>&1 &&
             echo complete || echo INCOMPLETE)
  echo "recording round $r: alone ${alone[-1]}, stock lcm-logger ${stock[-1]} (its log $complete), monitor --lcm-log ${own[-1]} steps/s"
  rm -f "$LOGDIR/stock$r.lcmlog" "$LOGDIR/own$r.lcmlog"
done
ma=$(median "${alone[@]}"); ms=$(median "${stock[@]}"); mo=$(median "${own[@]}")
echo "recording: medians [steps/s]: alone $ma, stock lcm-logger $ms ($(ratio "$ms" "$ma") of alone), monitor --lcm-log $mo ($(ratio "$mo" "$ma") of alone)"

# What other processes on the multicast group cost a round trip, for both placements: none, two
# liblcm subscribers to a channel nobody publishes, two batched readers (the monitor's and the
# trajectory's way of receiving, service/udpm_reader.hpp). A lockstep run has two such processes.
group() {
  local placement=$1 pin=() bare=() lcm=() batched=()
  if [ "$placement" = one-core ]; then pin=(taskset -c 0); fi
  for r in $(seq "$ROUNDS"); do
    for extra in none lcm batched; do
      local listeners=()
      if [ "$extra" != none ]; then
        local flag=(); [ "$extra" = batched ] && flag=(--batched)
        for i in 1 2; do "${pin[@]}" "$BUILD/bin/lcm-pingpong" listen "${flag[@]}" --seconds 60 --lcm-url "$URL" --prefix "G$i" & listeners+=($!); done
        sleep 0.2
      fi
      "${pin[@]}" "$BUILD/bin/lcm-pingpong-raw" server "$URL" "PG$placement$extra$r" & srv=$!
      rate=$("${pin[@]}" "$BUILD/bin/lcm-pingpong-raw" client "$URL" "PG$placement$extra$r" 15000 | awk '/pingpong_rate/ { print $2 }')
      wait $srv
      [ ${#listeners[@]} -gt 0 ] && { kill "${listeners[@]}"; wait "${listeners[@]}" 2>/dev/null || true; }
      case $extra in none) bare+=("$rate") ;; lcm) lcm+=("$rate") ;; batched) batched+=("$rate") ;; esac
    done
  done
  echo "$placement: raw ping-pong with other processes on the group, medians [round trips/s]:" \
       "none $(median "${bare[@]}"), two liblcm subscribers $(median "${lcm[@]}"), two batched readers $(median "${batched[@]}")"
}
group free
group one-core
auth
echo "bytes per step on the wire: $(jq -r .lockstep.bytes_per_step "$TMP/runfree1/summary.json") (target < 1024)"
