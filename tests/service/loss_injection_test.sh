#!/usr/bin/env bash
# Lost packets for real: an nftables rule in this test's namespace drops 3 % of the multicast
# packets at random (every role's messages: states, commands, references, status, resend
# requests). The run must still complete and be byte-identical to feeddrive-sim, and the
# monitor's LCM log (--lcm-log) must hold every step: what the monitor recovered by asking again
# is logged too, so feeddrive-log2csv gives the same file.
source "$(dirname "$0")/lib.sh" "$@"
# The rule must only ever drop packets in this test's own namespace, never on the host.
[ "${FEEDDRIVE_NETNS:-}" = private ] ||
  skip "no private network namespace (run through scripts/netns-run.sh as root or with CAP_SYS_ADMIN): the nftables rule would drop the host's multicast"
command -v nft >/dev/null || fail "nft (Debian package nftables, scripts/install-deps.sh) is not installed"
nft list tables >/dev/null 2>&1 || skip "nft cannot change the rules of this namespace (needs CAP_NET_ADMIN)"
trap 'nft delete table inet fdloss 2>/dev/null || true; jobs -p | xargs -r kill -9 2>/dev/null || true; rm -rf "$TMP"' EXIT
nft add table inet fdloss
nft add chain inet fdloss out '{ type filter hook output priority 0; }'
nft add rule inet fdloss out ip daddr 239.0.0.0/8 numgen random mod 100 '<' 3 counter drop
scen=$SRC/scenarios/paper/smc_bl_ramp_all_forces.yaml
sim_run "$scen" "$TMP/sim"
# An attached monitor (an observer, which never acknowledges) joins too: under the same loss it
# must recover every step it missed by asking, as the run's monitor does.
timeout 600 feeddrive-monitor "$scen" --attach --out "$TMP/attached" --no-plots -q --lcm-url "$URL" 2> "$TMP/attached.err" & m=$!
timeout 600 feeddrive-launch "$scen" --out "$TMP/mp" --no-plots -q --lcm-url "$URL" --lcm-log "$LOGDIR/mon.lcmlog"
wait $m || { tail -5 "$TMP/attached.err" >&2; fail "the attached monitor failed"; }
dropped=$(nft list chain inet fdloss out | sed -n 's/.*counter packets \([0-9]*\).*/\1/p')
[ "${dropped:-0}" -gt 100 ] || fail "the rule dropped only ${dropped:-0} packets"
same_csv "$TMP/sim/timeseries.csv" "$TMP/mp/timeseries.csv"
resends=$(json "$TMP/mp/summary.json" .lockstep.resends)
[ "$resends" -gt 0 ] || fail "no resends recorded although $dropped packets were dropped"
pass "$dropped packets dropped; $resends resends, $(json "$TMP/mp/summary.json" .lockstep.lost) recovered by the monitor, $(json "$TMP/mp/summary.json" .lockstep.duplicates) duplicates ignored; identical"
rows=$(( $(wc -l < "$TMP/attached/timeseries.csv") - 1 ))
missing=$(json "$TMP/attached/summary.json" .lockstep.missing_steps)
[ "$missing" = 0 ] || fail "the attached monitor skipped $missing steps under loss: $(jq -c .lockstep.gaps "$TMP/attached/summary.json")"
[ "$rows" -gt 0 ] || fail "the attached monitor recorded no row"
same_csv <(head -n 1 "$TMP/mp/timeseries.csv"; tail -n "$rows" "$TMP/mp/timeseries.csv") "$TMP/attached/timeseries.csv"
pass "the attached monitor under loss: $rows steps, $(json "$TMP/attached/summary.json" .lockstep.lost) asked for again, identical to the run's"
timeout 120 feeddrive-log2csv "$LOGDIR/mon.lcmlog" --scenario "$scen" --out "$TMP/conv" -q
same_csv "$TMP/mp/timeseries.csv" "$TMP/conv/timeseries.csv"
pass "the monitor's --lcm-log under loss converts to the same timeseries.csv"
