#!/usr/bin/env bash
# Speed of the in-process simulation against its floor and against SciPy's LSODA, measured side
# by side in one run (docs/performance.md). The paper's boundary-layer jerk-limited move
# (scenarios/paper/smc_bl_jerk_limited.yaml: LuGre, 10 kHz, 15,000 periods):
#   sim        fd-sim-only: the whole in-process loop (reference, controller, plant, record rows)
#   plant      fd-plant-replay: feeddrive's plant alone on the commands the loop applied
#   floor      cvode-floor deviation: bare CVODE, no feeddrive code, same variables, tolerances
#              and restart at each period (the same work: its steps and rhs counts are printed)
#   floor-pl   cvode-floor plain: bare CVODE on (x, v, z) itself (looser on position: rtol*|x|)
#   lsoda      SciPy LSODA (scipy.integrate.ode and odeint, the faster one is the baseline) on the
#              same system, tolerances, inputs and restarts (bench/lsoda_floor.py); also
#              solve_ivp(method='LSODA') (the usual interface, slower) and ode at rtol = 1e-11
#              (tighter, towards feeddrive's position accuracy)
# Each round runs every program once, in turn; medians over ROUNDS; the ratios are of medians of
# the same run. Run under the bench lock (the machine is shared):
#   flock /tmp/feeddrive-bench.lock bash bench/integrator_bench.sh [BUILD_DIR] [ROUNDS]
# Needs SciPy for the LSODA rows (Debian: apt-get install python3-scipy; it uses /usr/bin/python3
# when that has SciPy, else python3); without it those rows say so and the rest still runs.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
ROUNDS=${2:-7}
SCEN=scenarios/paper/smc_bl_jerk_limited.yaml
T=1e-4
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
for b in feeddrive-sim fd-sim-only fd-plant-replay cvode-floor; do
  [ -x "$BUILD/bin/$b" ] || { echo "integrator_bench: $BUILD/bin/$b is missing (cmake --build $BUILD --target $b)"; exit 2; }
done
PY=python3
if /usr/bin/python3 -c 'import scipy' 2> /dev/null; then PY=/usr/bin/python3; fi
HAVE_SCIPY=1
$PY -c 'import scipy' 2> /dev/null || HAVE_SCIPY=0

# The commands the closed loop applied (column u of timeseries.csv, 17 significant digits).
"$BUILD/bin/feeddrive-sim" "$SCEN" --out "$TMP/run" --no-plots -q
$PY - "$TMP/run/timeseries.csv" "$TMP/u.txt" "$TMP/final.txt" << 'PYEOF'
import csv, sys
rows = list(csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith('#')))
open(sys.argv[2], 'w').write("".join(r['u'] + "\n" for r in rows))
# The state after the last period is not a row; the last row's state is at t_{N-1}.
open(sys.argv[3], 'w').write(" ".join(rows[-1][k] for k in ('x', 'v', 'z')) + "\n")
PYEOF

: > "$TMP/times"
for r in $(seq "$ROUNDS"); do
  "$BUILD/bin/fd-sim-only" "$SCEN" | awk '{print "sim", $2}' >> "$TMP/times"
  "$BUILD/bin/fd-plant-replay" "$SCEN" "$TMP/u.txt" 1 | awk '{print "plant", $3, $7, $9, $11, $13, $15, $17}' >> "$TMP/times"
  "$BUILD/bin/cvode-floor" "$TMP/u.txt" $T deviation 1 | awk '{print "floor", $3, $7, $9, $11, $13, $15, $17}' >> "$TMP/times"
  "$BUILD/bin/cvode-floor" "$TMP/u.txt" $T plain 1 | awk '{print "floor-pl", $3, $7, $9, $11, $13, $15, $17}' >> "$TMP/times"
  if [ "$HAVE_SCIPY" = 1 ]; then
    $PY bench/lsoda_floor.py "$TMP/u.txt" $T ode 1 | awk '{print "lsoda-ode", $3, "-", "-", "-", $7, $9, $11}' >> "$TMP/times"
    $PY bench/lsoda_floor.py "$TMP/u.txt" $T odeint 1 | awk '{print "lsoda-odeint", $3, "-", "-", "-", $7, $9, $11}' >> "$TMP/times"
    $PY bench/lsoda_floor.py "$TMP/u.txt" $T ivp 1 | awk '{print "lsoda-ivp", $3, "-", "-", "-", $7, $9, $11}' >> "$TMP/times"
    $PY bench/lsoda_floor.py "$TMP/u.txt" $T ode 1 1e-11 | awk '{print "lsoda-ode-tight", $3, "-", "-", "-", $7, $9, $11}' >> "$TMP/times"
  fi
done

$PY - "$TMP/times" "$(wc -l < "$TMP/u.txt")" "$HAVE_SCIPY" << 'PYEOF'
import statistics, sys
periods, have_scipy = int(sys.argv[2]), sys.argv[3] == "1"
rows = {}
for line in open(sys.argv[1]):
    f = line.split()
    rows.setdefault(f[0], []).append(f[1:])
med = {k: statistics.median(float(r[0]) for r in v) for k, v in rows.items()}
names = {"sim": "feeddrive in-process loop (fd-sim-only)", "plant": "feeddrive plant alone (fd-plant-replay)",
         "floor": "bare CVODE floor, deviation form", "floor-pl": "bare CVODE, plain (x, v, z)",
         "lsoda-ode": "SciPy LSODA, integrate.ode", "lsoda-odeint": "SciPy LSODA, odeint",
         "lsoda-ivp": "SciPy LSODA, solve_ivp", "lsoda-ode-tight": "SciPy LSODA, integrate.ode, rtol 1e-11"}
print(f"{periods} periods, {len(rows['sim'])} rounds; medians")
print(f"{'':42s} {'s/run':>8s} {'periods/s':>10s} {'us/period':>9s} {'steps/p':>7s} {'rhs/p':>6s}  final x [m], v [m/s]")
for k in ["sim", "plant", "floor", "floor-pl", "lsoda-ode", "lsoda-odeint", "lsoda-ivp", "lsoda-ode-tight"]:
    if k not in rows: continue
    r = rows[k][0]
    steps = f"{int(r[1]) / periods:7.2f}" if len(r) > 1 and r[1] != "-" else "      -"
    rhs = f"{int(r[2]) / periods:6.2f}" if len(r) > 2 and r[2] != "-" else "     -"
    final = f"{r[4]}, {r[5]}" if len(r) > 5 else ""
    print(f"{names[k]:42s} {med[k]:8.4f} {periods / med[k]:10.0f} {med[k] / periods * 1e6:9.2f} {steps} {rhs}  {final}")
print(f"ratio sim / floor:   {med['sim'] / med['floor']:.2f}   (goal <= 1.5)")
print(f"ratio plant / floor: {med['plant'] / med['floor']:.2f}")
if have_scipy:
    best = min(med["lsoda-ode"], med["lsoda-odeint"])
    print(f"ratio LSODA (fastest interface) / sim:   {best / med['sim']:.2f}   (goal >= 30)")
    print(f"ratio LSODA (fastest interface) / floor: {best / med['floor']:.2f}")
    print(f"ratio LSODA solve_ivp / sim:             {med['lsoda-ivp'] / med['sim']:.2f}")
    print(f"ratio LSODA ode rtol 1e-11 / sim:        {med['lsoda-ode-tight'] / med['sim']:.2f}")
else:
    print("LSODA rows: SciPy is not installed (apt-get install python3-scipy); no LSODA ratio")
PYEOF
