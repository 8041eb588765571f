#!/usr/bin/env bash
# The pace at which the stock lcm-logger records a lockstep run without loss (--max-rate,
# service/loggers.hpp kStockLoggerSteps; docs/lcm-contract.md, "Recording with the stock
# lcm-logger"). Per rate: ROUNDS runs of smc_bl_ramp_all_forces (10,000 steps), each recorded by
# the stock lcm-logger at normal priority while stress-ng loads both cores (--cpu 2), converted
# with feeddrive-log2csv; prints the steps missing from each log.
# LOGGER_PRIO="chrt -f 20" runs the logger at real-time priority (as the docs recommend).
# Usage: flock /tmp/feeddrive-bench.lock scripts/netns-run.sh bash bench/logger_pace_bench.sh BUILD ROUNDS RATE...
#        (RATE 0: unpaced)
set -euo pipefail
BUILD=$(cd "${1:?build dir}" && pwd); ROUNDS=${2:-5}; shift 2
SRC=$(cd "$(dirname "$0")/.." && pwd)
URL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304'
scen=$SRC/scenarios/paper/smc_bl_ramp_all_forces.yaml
T=$(mktemp -d /dev/shm/fd-logger-bench.XXXXXX)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$T"' EXIT
stress-ng --cpu 2 --timeout 3600 -q & load=$!
sleep 1
echo "load: stress-ng --cpu 2 (pid $load); lcm-logger at ${LOGGER_PRIO:-normal priority}; $(uptime)"
for rate in "$@"; do
  drops=()
  for r in $(seq "$ROUNDS"); do
    ${LOGGER_PRIO:-} lcm-logger --lcm-url="$URL" --channel='FD_.*' --force -q "$T/run.lcmlog" & lg=$!
    sleep 0.5
    start=$(date +%s.%N)
    "$BUILD/bin/feeddrive-launch" "$scen" --out "$T/mon" --no-plots -q --lcm-url "$URL" --max-rate "$rate"
    wall=$(echo "$(date +%s.%N) - $start" | bc)
    sleep 0.3; kill -INT $lg; wait $lg || true
    "$BUILD/bin/feeddrive-log2csv" "$T/run.lcmlog" --scenario "$scen" --out "$T/conv" -q 2> "$T/conv.err" || true
    missing=$(jq '.log.missing_steps // 0' "$T/conv/summary.json" 2>/dev/null || echo "?")
    drops+=("$missing")
    gaps=$(jq -c ".log.gaps // []" "$T/conv/summary.json" 2>/dev/null | head -c 300)
    echo "rate $rate round $r: wall ${wall} s, steps missing from the stock log: $missing $gaps"
  done
  echo "RATE $rate: missing steps per run: ${drops[*]}"
done
