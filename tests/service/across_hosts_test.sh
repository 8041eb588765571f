#!/usr/bin/env bash
# Across machines: two network namespaces ("hosts") joined by a veth pair, LCM multicast with
# ttl=1 between them. Host A runs the plant, trajectory and monitor (feeddrive-launch with
# --external controller); host B runs the controller. The run must complete identical to
# feeddrive-sim. Set-up as in docs/deployment.md: an address per host, a multicast route
# 239.0.0.0/8 on the veth, multicast on.
source "$(dirname "$0")/lib.sh" "$@"
command -v ip >/dev/null || fail "ip (Debian package iproute2, scripts/install-deps.sh) is not installed"
A=fdA$$; B=fdB$$
ip netns add "$A" 2>/dev/null || skip "cannot create named network namespaces (ip netns add needs root)"
ip netns del "$A"
cleanup_ns() { ip netns del "$A" 2>/dev/null || true; ip netns del "$B" 2>/dev/null || true; }
trap 'cleanup_ns; jobs -p | xargs -r kill -9 2>/dev/null || true; rm -rf "$TMP"' EXIT
ip netns add "$A"; ip netns add "$B"
ip link add "va$$" type veth peer name "vb$$"
ip link set "va$$" netns "$A"; ip link set "vb$$" netns "$B"
ip -n "$A" addr add 10.77.0.1/24 dev "va$$"; ip -n "$B" addr add 10.77.0.2/24 dev "vb$$"
for ns in "$A" "$B"; do
  dev=$([ "$ns" = "$A" ] && echo "va$$" || echo "vb$$")
  ip -n "$ns" link set lo up
  ip -n "$ns" link set "$dev" up multicast on
  ip -n "$ns" route add 239.0.0.0/8 dev "$dev"
done
LAN='udpm://239.255.76.67:7667?ttl=1&recv_buf_size=4194304'
scen=$SRC/tests/service/scenarios/short_jerk.yaml
sim_run "$scen" "$TMP/sim"
ip netns exec "$A" timeout 120 "$BIN/feeddrive-launch" "$scen" --out "$TMP/mp" --no-plots -q --external controller --lcm-url "$LAN" & l=$!
ip netns exec "$B" timeout 120 "$BIN/feeddrive-controller" "$scen" -q --lcm-url "$LAN" & c=$!
wait $l || fail "launch on host A failed"
wait $c || fail "the controller on host B failed"
same_csv "$TMP/sim/timeseries.csv" "$TMP/mp/timeseries.csv"
pass "plant on host A, controller on host B over a veth with ttl=1: identical; state->command p50 $(json "$TMP/mp/summary.json" .lockstep.latency_us.state_to_command.p50) us"
