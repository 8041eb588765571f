#!/usr/bin/env bash
# feeddrive-study under real Open MPI: `mpirun -np 3` on this machine gives the same results.csv,
# byte for byte, as the run without MPI; a bad study under mpirun exits non-zero without hanging.
# Runs in a private network namespace (scripts/netns-run.sh, from ctest) and restricts Open MPI to
# shared memory and loopback, so nothing leaves the machine.
# Arguments: SOURCE_DIR BUILD_DIR
set -euo pipefail
SRC=$(cd "$1" && pwd)
BUILD=$(cd "$2" && pwd)
STUDY=$BUILD/bin/feeddrive-study
skip() { echo "SKIPPED: $*"; exit 0; }
fail() { echo "FAIL: $*" >&2; exit 1; }
command -v mpirun >/dev/null || skip "mpirun not installed (openmpi-bin)"
TMP=$(mktemp -d "${TMPDIR:-/tmp}/feeddrive-mpi.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
# Open MPI: shared memory (vader) and self only, its runtime on loopback; as root when the test
# runs as root (CI containers); no single-copy mechanism (ptrace may be forbidden in containers).
MPIRUN=(mpirun --oversubscribe --mca btl self,vader --mca btl_vader_single_copy_mechanism none
        --mca oob_tcp_if_include lo --mca btl_tcp_if_include lo --bind-to none)
if [ "$(id -u)" -eq 0 ]; then MPIRUN+=(--allow-run-as-root); fi

cat > "$TMP/study.yaml" <<YAML
name: mpi
base: $SRC/scenarios/paper/smc_bl_jerk_limited.yaml
set: {duration: 0.05}
controllers:
  - {name: smc, scenario: $SRC/scenarios/paper/smc_bl_jerk_limited.yaml}
  - {name: cascade, controller: {type: cascade, kv: 3000}}
families:
  - name: nominal
  - name: mass
    grid: [{key: plant.mass, scale: [0.8, 1.2]}]
  - name: mc
    monte_carlo:
      draws: 6
      seed: 3
      parameters:
        - {keys: [plant.friction.static_force, plant.friction.coulomb_force], distribution: uniform, low: 0.7, high: 1.3, scale: true}
        - {key: plant.effects.input_delay.delay, distribution: lognormal, mu: -9.2, sigma: 0.5}
  - name: broken
    set: {plant.integrator.max_steps: 1}
YAML

timeout 300 "$STUDY" "$TMP/study.yaml" --out "$TMP/local" -q --no-plots || fail "local run failed"
timeout 300 "${MPIRUN[@]}" -np 3 "$STUDY" "$TMP/study.yaml" --out "$TMP/mpi" -q --no-plots || fail "mpirun -np 3 failed"
ranks=$(jq -r .ranks "$TMP/mpi/timing.json")
[ "$ranks" = 3 ] || fail "timing.json says $ranks ranks, expected 3"
rows=$(($(wc -l < "$TMP/local/results.csv") - 1))
[ "$rows" = 20 ] || fail "expected 20 cases, results.csv has $rows"
grep -q ",broken,.*,false,\"CVODE" "$TMP/mpi/results.csv" || fail "the failed case is not reported under MPI"
cmp "$TMP/local/results.csv" "$TMP/mpi/results.csv" || fail "results.csv differs between the local run and mpirun -np 3"
echo "PASS: mpirun -np 3 gives the local results.csv byte for byte ($rows cases)"

# A rerun under MPI reuses every case; the file stays the same.
timeout 300 "${MPIRUN[@]}" -np 2 "$STUDY" "$TMP/study.yaml" --out "$TMP/mpi" -q --no-plots || fail "mpirun rerun failed"
[ "$(jq -r .cases_run "$TMP/mpi/timing.json")" = 0 ] || fail "the rerun ran cases again"
cmp "$TMP/local/results.csv" "$TMP/mpi/results.csv" || fail "results.csv changed on the rerun"
echo "PASS: a rerun under mpirun reuses every case"

# A bad study: every rank stops, mpirun returns non-zero, within the timeout.
printf 'name: bad\nbase: %s/scenarios/paper/smc_bl_jerk_limited.yaml\nfamilies:\n  - {name: f, grid: [{key: plant.frction.static_force, values: [1]}]}\n' "$SRC" > "$TMP/bad.yaml"
set +e
timeout 120 "${MPIRUN[@]}" -np 3 "$STUDY" "$TMP/bad.yaml" --out "$TMP/bad" -q 2> "$TMP/bad.err"
rc=$?
set -e
[ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] || fail "a bad study under mpirun gave exit $rc (124: it hung)"
grep -q "plant.frction: unknown key" "$TMP/bad.err" || fail "no one-line error: $(head -3 "$TMP/bad.err")"
[ ! -e "$TMP/bad" ] || fail "a bad study wrote its folder"
echo "PASS: a bad study under mpirun stops every rank (exit $rc)"
