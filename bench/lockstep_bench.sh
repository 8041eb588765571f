#!/usr/bin/env bash
# Lockstep speed against its ceiling, measured in the same run (run inside a private network
# namespace: scripts/netns-run.sh bench/lockstep_bench.sh [BUILD_DIR] [ROUNDS]):
#   1. a raw LCM ping-pong between two processes (bench/lcm_pingpong.cpp): one round trip per step;
#   2. the four-process lockstep run (plant + controller + trajectory + monitor) of the paper's
#      boundary-layer jerk-limited move, 15,000 steps; steps/s from the monitor (first to last step).
# Each is run ROUNDS times (default 3), alternating; medians and their ratio are printed, for
# two placements: free (the scheduler's) and one core (all processes of both pinned to CPU 0).
# Target: lockstep >= 0.8 x ping-pong. Message sizes are printed too (target < 1 KB per step).
# Then, what other processes on the multicast group cost a ping-pong round trip (the reason the
# monitor and the trajectory read in batches; docs/lcm-contract.md, "Receiving in batches").
# Last, the cost of authentication (--key, HMAC-SHA256 on every message; docs/security.md): the
# same lockstep run without and with a key, alternating, medians, ratio and cost per step.
# A third argument "auth" runs only that part: bench/lockstep_bench.sh BUILD ROUNDS auth
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
ROUNDS=${2:-3}
URL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304'
TMP=$(mktemp -d)
trap 'jobs -p | xargs -r kill 2>/dev/null || true; rm -rf "$TMP"' EXIT
median() { printf '%s\n' "$@" | sort -g | awk '{ a[NR] = $1 } END { print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }
# bench PLACEMENT: "free" (the scheduler places the processes) or "one-core" (every process of
# both benchmarks pinned to CPU 0: taskset for the ping-pong, feeddrive-launch --cpus 0).
bench() {
  local placement=$1 pin=() cpus=() pp=() ls_rates=()
  if [ "$placement" = one-core ]; then pin=(taskset -c 0); cpus=(--cpus 0); fi
  for r in $(seq "$ROUNDS"); do
    "${pin[@]}" "$BUILD/bin/lcm-pingpong" server --lcm-url "$URL" --prefix "PP$placement$r" & srv=$!
    rate=$("${pin[@]}" "$BUILD/bin/lcm-pingpong" client --count 15000 --lcm-url "$URL" --prefix "PP$placement$r" |
           awk '/pingpong_rate/ { print $2 }')
    wait $srv
    pp+=("$rate")
    "$BUILD/bin/feeddrive-launch" scenarios/paper/smc_bl_jerk_limited.yaml --out "$TMP/run$placement$r" --no-plots -q \
        --lcm-url "$URL" --prefix "LS$placement$r" "${cpus[@]}"
    ls_rates+=("$(jq -r .lockstep.steps_per_second "$TMP/run$placement$r/summary.json")")
    echo "$placement round $r: ping-pong ${pp[-1]} round trips/s, lockstep ${ls_rates[-1]} steps/s"
  done
  local mp ml
  mp=$(median "${pp[@]}"); ml=$(median "${ls_rates[@]}")
  echo "$placement: median ping-pong $mp round trips/s, median lockstep $ml steps/s (4 processes, CVODE plant, sliding-mode controller)"
  awk -v l="$ml" -v p="$mp" -v w="$placement" 'BEGIN { printf "%s: ratio lockstep / ping-pong: %.3f (target >= 0.8)\n", w, l / p }'
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
if [ "${3:-all}" = auth ]; then
  auth
  exit 0
fi
bench free
bench one-core
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
      "${pin[@]}" "$BUILD/bin/lcm-pingpong" server --lcm-url "$URL" --prefix "PG$placement$extra$r" & srv=$!
      rate=$("${pin[@]}" "$BUILD/bin/lcm-pingpong" client --count 15000 --lcm-url "$URL" --prefix "PG$placement$extra$r" |
             awk '/pingpong_rate/ { print $2 }')
      wait $srv
      [ ${#listeners[@]} -gt 0 ] && { kill "${listeners[@]}"; wait "${listeners[@]}" 2>/dev/null || true; }
      case $extra in none) bare+=("$rate") ;; lcm) lcm+=("$rate") ;; batched) batched+=("$rate") ;; esac
    done
  done
  echo "$placement: ping-pong with other processes on the group, medians [round trips/s]:" \
       "none $(median "${bare[@]}"), two liblcm subscribers $(median "${lcm[@]}"), two batched readers $(median "${batched[@]}")"
}
group free
group one-core
auth
echo "bytes per step on the wire: $(jq -r .lockstep.bytes_per_step "$TMP/runfree1/summary.json") (target < 1024)"
