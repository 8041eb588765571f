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
# the same run. Each program times its own loop (start-up and loading excluded), as CPU time of
# the process (the figure quoted: other work on a shared machine barely moves it) and wall time. Run under the bench lock (the machine is shared):
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
# Every program prints "key value" pairs; keep: name, wall s, CPU s, steps, rhs evals, final x, v.
keep() { awk -v name="$1" '{ for (i = 1; i < NF; i++) kv[$i] = $(i + 1)
  w = ("seconds" in kv) ? kv["seconds"] : kv["sim_only_seconds"]; c = ("cpu" in kv) ? kv["cpu"] : kv["cpu_seconds"]
  print name, w, c, ("steps" in kv && name != "sim") ? kv["steps"] : "-", ("rhs" in kv) ? kv["rhs"] : "-",
        ("x" in kv) ? kv["x"] : "-", ("v" in kv) ? kv["v"] : "-" }' >> "$TMP/times"; }
for r in $(seq "$ROUNDS"); do
  "$BUILD/bin/fd-sim-only" "$SCEN" | keep sim
  "$BUILD/bin/fd-plant-replay" "$SCEN" "$TMP/u.txt" 1 | keep plant
  "$BUILD/bin/cvode-floor" "$TMP/u.txt" $T deviation 1 | keep floor
  "$BUILD/bin/cvode-floor" "$TMP/u.txt" $T plain 1 | keep floor-pl
  if [ "$HAVE_SCIPY" = 1 ]; then
    $PY bench/lsoda_floor.py "$TMP/u.txt" $T ode 1 | keep lsoda-ode
    $PY bench/lsoda_floor.py "$TMP/u.txt" $T odeint 1 | keep lsoda-odeint
    $PY bench/lsoda_floor.py "$TMP/u.txt" $T ivp 1 | keep lsoda-ivp
    $PY bench/lsoda_floor.py "$TMP/u.txt" $T ode 1 1e-11 | keep lsoda-ode-tight
  fi
done

$PY - "$TMP/times" "$(wc -l < "$TMP/u.txt")" "$HAVE_SCIPY" << 'PYEOF'
import statistics, sys
periods, have_scipy = int(sys.argv[2]), sys.argv[3] == "1"
rows = {}
for line in open(sys.argv[1]):
    f = line.split()
    rows.setdefault(f[0], []).append(f[1:])
wall = {k: statistics.median(float(r[0]) for r in v) for k, v in rows.items()}
cpu = {k: statistics.median(float(r[1]) for r in v) for k, v in rows.items()}
names = {"sim": "feeddrive in-process loop (fd-sim-only)", "plant": "feeddrive plant alone (fd-plant-replay)",
         "floor": "bare CVODE floor, deviation form", "floor-pl": "bare CVODE, plain (x, v, z)",
         "lsoda-ode": "SciPy LSODA, integrate.ode", "lsoda-odeint": "SciPy LSODA, odeint",
         "lsoda-ivp": "SciPy LSODA, solve_ivp", "lsoda-ode-tight": "SciPy LSODA, integrate.ode, rtol 1e-11"}
print(f"{periods} periods, {len(rows['sim'])} rounds; medians of the CPU time (and wall time) of each loop")
print(f"{'':40s} {'CPU s':>7s} {'wall s':>7s} {'periods/s':>9s} {'us/per':>7s} {'steps/p':>7s} {'rhs/p':>6s}  final x [m], v [m/s]")
for k in names:
    if k not in rows: continue
    r = rows[k][0]
    steps = f"{int(r[2]) / periods:7.2f}" if r[2] != "-" else "      -"
    rhs = f"{int(r[3]) / periods:6.2f}" if r[3] != "-" else "     -"
    final = f"{r[4]}, {r[5]}" if r[4] != "-" else ""
    print(f"{names[k]:40s} {cpu[k]:7.4f} {wall[k]:7.4f} {periods / cpu[k]:9.0f} {cpu[k] / periods * 1e6:7.2f} {steps} {rhs}  {final}")
def ratio(label, a, b, goal=""):
    print(f"{label:42s} CPU {a[0] / b[0]:6.2f}   wall {a[1] / b[1]:6.2f}   {goal}")
pair = lambda k: (cpu[k], wall[k])
ratio("ratio sim / floor", pair("sim"), pair("floor"), "(goal <= 1.5)")
ratio("ratio plant / floor", pair("plant"), pair("floor"))
if have_scipy:
    fast = min(("lsoda-ode", "lsoda-odeint"), key=lambda k: cpu[k])
    ratio(f"ratio LSODA ({fast[6:]}, fastest) / sim", pair(fast), pair("sim"), "(goal >= 30)")
    ratio(f"ratio LSODA ({fast[6:]}, fastest) / floor", pair(fast), pair("floor"))
    ratio("ratio LSODA solve_ivp / sim", pair("lsoda-ivp"), pair("sim"))
    ratio("ratio LSODA ode rtol 1e-11 / sim", pair("lsoda-ode-tight"), pair("sim"))
else:
    print("LSODA rows: SciPy is not installed (apt-get install python3-scipy); no LSODA ratio")
PYEOF
