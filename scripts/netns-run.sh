#!/usr/bin/env bash
# Runs a command inside a private network namespace whose loopback carries LCM multicast:
#   unshare -n; ip link set lo up; ip link set lo multicast on; ip route add 239.0.0.0/8 dev lo
# No packet leaves the namespace, and runs in parallel namespaces never hear each other.
# Without the privileges for a namespace it says so and falls back to the host loopback; the
# LCM URLs of feeddrive use ttl=0 there too.
# The command sees FEEDDRIVE_NETNS=private (its own namespace) or FEEDDRIVE_NETNS=host (the
# fallback), so tests that change network settings (nftables, veth pairs) can refuse to touch
# the host's.
set -euo pipefail
if [ "$#" -eq 0 ]; then echo "usage: netns-run.sh COMMAND [ARGS...]" >&2; exit 2; fi
if unshare -n true 2>/dev/null; then
  export FEEDDRIVE_NETNS=private
  exec unshare -n bash -c 'ip link set lo up && ip link set lo multicast on && ip route add 239.0.0.0/8 dev lo && exec "$@"' netns-run "$@"
fi
echo "netns-run: cannot create a network namespace (needs root or CAP_SYS_ADMIN): falling back to the host loopback, ttl=0" >&2
export FEEDDRIVE_NETNS=host
exec "$@"
