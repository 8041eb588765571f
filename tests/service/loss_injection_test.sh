#!/usr/bin/env bash
# Lost packets for real: an nftables rule in this test's namespace drops 3 % of the multicast
# packets at random (every role's messages: states, commands, references, status, resend
# requests). The run must still complete and be byte-identical to feeddrive-sim.
source "$(dirname "$0")/lib.sh" "$@"
command -v nft >/dev/null || fail "nft (Debian package nftables) is not installed"
nft add table inet fdloss
nft add chain inet fdloss out '{ type filter hook output priority 0; }'
nft add rule inet fdloss out ip daddr 239.0.0.0/8 numgen random mod 100 '<' 3 counter drop
scen=$SRC/scenarios/paper/smc_bl_ramp_all_forces.yaml
sim_run "$scen" "$TMP/sim"
timeout 600 feeddrive-launch "$scen" --out "$TMP/mp" --no-plots -q --lcm-url "$URL"
dropped=$(nft list chain inet fdloss out | sed -n 's/.*counter packets \([0-9]*\).*/\1/p')
[ "${dropped:-0}" -gt 100 ] || fail "the rule dropped only ${dropped:-0} packets"
same_csv "$TMP/sim/timeseries.csv" "$TMP/mp/timeseries.csv"
resends=$(json "$TMP/mp/summary.json" .lockstep.resends)
[ "$resends" -gt 0 ] || fail "no resends recorded although $dropped packets were dropped"
pass "$dropped packets dropped; $resends resends, $(json "$TMP/mp/summary.json" .lockstep.lost) recovered by the monitor, $(json "$TMP/mp/summary.json" .lockstep.duplicates) duplicates ignored; identical"
