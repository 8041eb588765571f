#!/usr/bin/env python3
"""SciPy's LSODA on the same three-state system and inputs as bench/cvode_floor.c
(bench/integrator_bench.sh measures both, and feeddrive, in one run).

    x' = v
    v' = (Ka*Kf*u - sigma0*z - sigma1*z' - sigma2*v) / m
    z' = v - sigma0*|v|*z/g(v),   g(v) = Fc + (Fs - Fc)*exp(-(v/vs)^2)      (Canudas de Wit 1995)

Xie & Liang Table 1 values; rtol = 1e-8, atol = (1e-12 m, 1e-12 m/s, 1e-13 m) as feeddrive; the
analytic Jacobian; u_k held over [kT, (k+1)T] and the integrator restarted every period, as
feeddrive and the CVODE floor do. Two interfaces, both LSODA (ODEPACK) underneath:
  ode     scipy.integrate.ode('lsoda'): set_initial_value restarts it each period;
  odeint  scipy.integrate.odeint, one call per period.
  ivp     scipy.integrate.solve_ivp(method='LSODA'), one call per period: the interface most
          SciPy users reach for; its per-call Python overhead makes it several times slower.
The fastest of them is the baseline (its Python right-hand side is the cost SciPy users pay).
An optional RTOL replaces 1e-8 (the absolute tolerances stay): on the plain variables LSODA's
position error is rtol*|x|-bound, so matching feeddrive's accuracy needs a tighter rtol.

Usage: lsoda_floor.py U_FILE PERIOD ode|odeint|ivp REPEATS [RTOL]
Prints one line per repeat: "<interface> seconds S periods N x X v V z Z cpu C" (S wall time, C the
process's CPU time, of the loop).
Needs SciPy: apt-get install python3-scipy (Debian) or pip install scipy.
"""
import math
import sys
import time

try:
    from scipy.integrate import ode, odeint, solve_ivp
except ImportError:
    sys.exit("lsoda_floor: SciPy is not installed (apt-get install python3-scipy, or pip install scipy)")

M, KAKF = 102.04, 260.0
FS, FC, VS, S0, S1, S2 = 120.0, 80.0, 0.1, 2e6, 2e4, 0.4
RTOL, ATOL = 1e-8, [1e-12, 1e-12, 1e-13]
exp, fabs = math.exp, math.fabs


def f(t, y, u):
    v, z = y[1], y[2]
    r = v / VS
    g = FC + (FS - FC) * exp(-r * r)
    zdot = v - S0 * fabs(v) * z / g
    return [v, (KAKF * u - S0 * z - S1 * zdot - S2 * v) / M, zdot]


def jac(t, y, u):
    v, z = y[1], y[2]
    r = v / VS
    e = exp(-r * r)
    g = FC + (FS - FC) * e
    dg = -(FS - FC) * e * 2.0 * v / (VS * VS)
    sg = (v > 0.0) - (v < 0.0)
    a_zv = 1.0 - S0 * z * (sg * g - fabs(v) * dg) / (g * g)
    a_zz = -S0 * fabs(v) / g
    return [[0.0, 1.0, 0.0],
            [0.0, -(S1 * a_zv + S2) / M, -(S0 + S1 * a_zz) / M],
            [0.0, a_zv, a_zz]]


def run_ode(us, T):
    r = ode(f, jac).set_integrator("lsoda", rtol=RTOL, atol=ATOL, nsteps=100000)
    y = [0.0, 0.0, 0.0]
    for k, u in enumerate(us):
        r.set_initial_value(y, k * T).set_f_params(u).set_jac_params(u)
        y = r.integrate((k + 1) * T)
        if not r.successful():
            sys.exit(f"lsoda_floor: LSODA failed in period {k}")
    return y


def run_odeint(us, T):
    y = [0.0, 0.0, 0.0]
    for k, u in enumerate(us):
        out = odeint(f, y, [k * T, (k + 1) * T], args=(u,), Dfun=jac, rtol=RTOL, atol=ATOL, mxstep=100000,
                     tfirst=True)
        y = out[1]
    return y


def run_ivp(us, T):
    y = [0.0, 0.0, 0.0]
    for k, u in enumerate(us):
        sol = solve_ivp(f, (k * T, (k + 1) * T), y, method="LSODA", args=(u,), jac=jac, rtol=RTOL, atol=ATOL)
        if not sol.success:
            sys.exit(f"lsoda_floor: solve_ivp failed in period {k}: {sol.message}")
        y = sol.y[:, -1]
    return y


def main():
    global RTOL
    if len(sys.argv) not in (5, 6) or sys.argv[3] not in ("ode", "odeint", "ivp"):
        sys.exit("usage: lsoda_floor.py U_FILE PERIOD ode|odeint|ivp REPEATS [RTOL]")
    with open(sys.argv[1]) as fh:
        us = [float(line) for line in fh if line.strip()]
    T, how, repeats = float(sys.argv[2]), sys.argv[3], int(sys.argv[4])
    if len(sys.argv) == 6:
        RTOL = float(sys.argv[5])
    run = {"ode": run_ode, "odeint": run_odeint, "ivp": run_ivp}[how]
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        y = run(us, T)
        sec, cpu = time.perf_counter() - t0, time.process_time() - c0
        print(f"{how} seconds {sec:.6f} periods {len(us)} x {y[0]:.12g} v {y[1]:.12g} z {y[2]:.12g} cpu {cpu:.6f}",
              flush=True)


if __name__ == "__main__":
    main()
