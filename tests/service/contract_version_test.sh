#!/usr/bin/env bash
# A participant of an older contract is named within 1 s in one line that says what to update, and
# the run fails at once instead of at a timeout (docs/lcm-contract.md, Versions):
#   1. a controller speaking contract version 2: its heartbeat (a process_status_t without
#      contract_version, LCM fingerprint 0x82c6d4827f2f3fed) sent as raw LCM datagrams;
#   2. a controller that sends run id 0 (the C sketch of docs/external-controllers.md with its
#      run id copy removed, as a client written before run ids);
#   3. a plant of another run on the group (heartbeats of run id 999) beside the run's own plant:
#      named once within 1 s, and the run completes (an extra sender is no reason to end it);
#   4. a controller speaking contract version 3: its heartbeat decodes (process_status_t did not
#      change in version 4) and says contract_version 3; named with both versions in one line, and
#      the run fails at once.
source "$(dirname "$0")/lib.sh" "$@"
command -v cc > /dev/null || skip "no C compiler"
scen=$SRC/scenarios/paper/smc_bl_jerk_limited.yaml
port=${URL#udpm://*:}; port=${port%%\?*}

# 1. Version 2 heartbeats of a "controller", one every 100 ms, on the run's group (LCM's small-
# message datagram: "LC02", sequence number, channel, NUL, payload; lcm-proj.github.io wire format).
cat > "$TMP/v2.py" <<'PY'
import socket, struct, sys, time
port, run_id, role = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
v3 = len(sys.argv) > 4  # version 3 or later: run_nonce (int64) after utime, contract_version (int32) before mac_size
# lcm-gen's C source holds the type's base hash; the fingerprint on the wire is it rotated left by 1.
fp3 = (((int(sys.argv[4], 16) << 1) & (2**64 - 1)) | (int(sys.argv[4], 16) >> 63)) if v3 else 0
version = int(sys.argv[5]) if len(sys.argv) > 5 else 4  # the contract_version the heartbeat says
def s(x): b = x.encode() + b"\0"; return struct.pack(">i", len(b)) + b
s_ = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s_.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
for n in range(100):
    body = (struct.pack(">Qqq", fp3 if v3 else 0x82c6d4827f2f3fed, run_id, int(time.time() * 1e6))
            + (struct.pack(">q", 0) if v3 else b"")
            + s(role) + s("running") + struct.pack(">qq", 0, -1) + s("") + struct.pack(">qqqqqq", 0, 0, 0, 0, 0, 0)
            + (struct.pack(">i", version) if v3 else b"") + struct.pack(">h", 0))
    s_.sendto(b"LC02" + struct.pack(">I", n) + b"FD_STATUS\0" + body, ("239.255.76.67", port))
    time.sleep(0.1)  # a heartbeat every 100 ms: a rate, not a wait
PY
timeout 60 feeddrive-launch "$scen" --out "$TMP/v2" --no-plots -q --lcm-url "$URL" --run-id 77 --external controller 2> "$TMP/v2.err" & l=$!
wait_on_bus $l feeddrive-monitor  # the run's monitor hears the heartbeats from the first one
start=$(date +%s.%N)
timeout 20 python3 "$TMP/v2.py" "$port" 77 controller & p=$!
set +e; wait $l; rc=$?; set -e
took=$(echo "$(date +%s.%N) - $start" | bc)
kill $p 2>/dev/null || true
[ $rc = 1 ] || { cat "$TMP/v2.err"; fail "version 2: exit $rc"; }
[ "$(grep -c "monitor: the controller speaks contract version 2 (a process_status_t of 24 November 2026 on FD_STATUS); this run speaks 4: rebuild it with this feeddrive's lcmtypes/" "$TMP/v2.err")" = 1 ] ||
  { cat "$TMP/v2.err"; fail "version 2: no single line naming it"; }
# Named within 1 s of its first heartbeat; the launcher's exit follows within 1 s (its grace after
# a monitor failure) because the plant and the trajectory stop on the monitor's failed status.
awk -v t="$took" 'BEGIN { exit !(t < 2.5) }' || { cat "$TMP/v2.err"; fail "version 2: took $took s"; }
pass "a version 2 controller: exit 1 after $took s, named in one line"

# 2. Run id 0: the docs' C sketch stamping 0 on its commands and heartbeats.
mkdir -p "$TMP/gen"
lcm-gen -c --c-cpath "$TMP/gen" --c-hpath "$TMP/gen" "$SRC"/lcmtypes/*.lcm
awk '/^## 7\. A C sketch/ { s = 1 } s && /^```c$/ { c = 1; next } c && /^```$/ { exit } c' \
  "$SRC/docs/external-controllers.md" | sed 's/= info\.run_id;/= 0;/' > "$TMP/controller.c"
grep -q "run_id = 0;" "$TMP/controller.c" || fail "could not make the sketch send run id 0"
cc -O2 -Wall -Wno-unused-parameter -I"$TMP/gen" "$TMP/controller.c" "$TMP"/gen/*.c -llcm -lm -o "$TMP/controller0"
timeout 60 "$TMP/controller0" "$URL" FD 2> /dev/null & c=$!
set +e
timeout 60 feeddrive-launch "$scen" --out "$TMP/zero" --no-plots -q --lcm-url "$URL" --external controller 2> "$TMP/zero.err"; rc=$?
set -e
kill $c 2>/dev/null || true
[ $rc = 1 ] || { cat "$TMP/zero.err"; fail "run id 0: exit $rc"; }
[ "$(grep -c "monitor: the controller publishes run id 0 on FD_[A-Z]*: a client older than run ids" "$TMP/zero.err")" = 1 ] ||
  { cat "$TMP/zero.err"; fail "run id 0: no single line naming the controller"; }
grep -q "failed: monitor" "$TMP/zero.err" || fail "run id 0: the monitor did not fail the run"
pass "a controller sending run id 0: exit 1, $(grep -m1 -o "the controller publishes run id 0 on FD_[A-Z]*" "$TMP/zero.err")"

# 3. Another run's plant (heartbeats of this contract, run id 999) beside this run's own plant.
# The fingerprint of process_status_t: from lcm-gen's C source of this build's types.
fp=$(grep -o "0x[0-9a-f]*LL" "$TMP/gen/feeddrive_process_status_t.c" | head -n 1 | sed 's/LL$//')
[ -n "$fp" ] || fail "no fingerprint in the generated process_status_t"
timeout 60 feeddrive-launch "$SRC/scenarios/paper/smc_bl_ramp_all_forces.yaml" --out "$TMP/other" --no-plots -q \
  --lcm-url "$URL" --run-id 78 2> "$TMP/other.err" & l=$!
wait_on_bus $l feeddrive-monitor
timeout 20 python3 "$TMP/v2.py" "$port" 999 plant "$fp" & p=$!
wait $l || { cat "$TMP/other.err"; fail "another run's plant on the group: the run failed"; }
kill $p 2>/dev/null || true
[ "$(grep -c "monitor: the plant of another run (run id 999; this run 78) publishes on FD_STATUS" "$TMP/other.err")" = 1 ] ||
  { cat "$TMP/other.err"; fail "another run's plant: not named in one line"; }
pass "another run's plant on the group: named once, the run completed"

# 4. A version 3 controller of this run: the heartbeat of this build's process_status_t (version 4
# did not change it) saying contract_version 3, every 100 ms.
timeout 60 feeddrive-launch "$scen" --out "$TMP/v3" --no-plots -q --lcm-url "$URL" --run-id 79 --external controller 2> "$TMP/v3.err" & l=$!
wait_on_bus $l feeddrive-monitor
start=$(date +%s.%N)
timeout 20 python3 "$TMP/v2.py" "$port" 79 controller "$fp" 3 & p=$!
set +e; wait $l; rc=$?; set -e
took=$(echo "$(date +%s.%N) - $start" | bc)
kill $p 2>/dev/null || true
[ $rc = 1 ] || { cat "$TMP/v3.err"; fail "version 3: exit $rc"; }
[ "$(grep -c "monitor: the controller speaks contract version 3; this run speaks 4: rebuild it with this feeddrive's lcmtypes/ (docs/lcm-contract.md, Versions)" "$TMP/v3.err")" = 1 ] ||
  { cat "$TMP/v3.err"; fail "version 3: no single line naming it with both versions"; }
awk -v t="$took" 'BEGIN { exit !(t < 2.5) }' || { cat "$TMP/v3.err"; fail "version 3: took $took s"; }
pass "a version 3 controller: exit 1 after $took s, named in one line with both versions"
