/* The floor of the in-process simulation: a bare CVODE loop with no feeddrive code
 * (bench/integrator_bench.sh compares feeddrive against it and against SciPy's LSODA).
 *
 * The same three-state system as scenarios/paper/smc_bl_jerk_limited.yaml's plant (LuGre
 * friction, Xie & Liang Table 1 values, delta = 2, no ripple, no grinding):
 *   x' = v
 *   v' = (Ka*Kf*u - sigma0*z - sigma1*z' - sigma2*v) / m
 *   z' = v - sigma0*|v|*z/g(v),   g(v) = Fc + (Fs - Fc)*exp(-(v/vs)^2)      (Canudas de Wit 1995)
 * with the same method and tolerances as plant/src/cvode_integrator.cpp (BDF, Newton, dense
 * direct solver, analytic Jacobian, rtol = 1e-8, atol = 1e-12 m, 1e-12 m/s, 1e-13 m), the input
 * u_k held over each period [kT, (k+1)T] and CVODE restarted (CVodeReInit) at every period.
 * The inputs u_k are read from a file (one per line), the commands the closed-loop run applied.
 *
 * Two formulations (argument FORM):
 *   plain      CVODE integrates (x, v, z) itself. Its error weight on x is rtol*|x| + atol, so
 *              at x = 0.1 m it allows ~1e-9 m per step: looser than feeddrive on positions.
 *   deviation  CVODE integrates z and the deviations of x, v from the period's Taylor prediction
 *              x0 + v0*tau + a0*tau^2/2 + j0*tau^3/6 (the change of variables feeddrive uses, so
 *              position errors are bounded by atol, not by rtol*|x|): the same accuracy as
 *              feeddrive, the floor feeddrive is compared against.
 *
 * Usage: cvode-floor U_FILE PERIOD FORM REPEATS
 * Prints one line per repeat: "<form> seconds S periods N steps ST rhs RHS jac J x X v V z Z cpu C"
 * (S wall time, C the process's CPU time, of the loop).
 */
#include <cvode/cvode.h>
#include <math.h>
#include <nvector/nvector_serial.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <time.h>

/* Xie & Liang Table 1 (the feeddrive defaults, docs/parameters.md). */
static const double kMass = 102.04, kThrustGain = 260.0;
static const double kFs = 120.0, kFc = 80.0, kVs = 0.1, kS0 = 2e6, kS1 = 2e4, kS2 = 0.4;

typedef struct {
  double u;
  int deviation;
  double t0, x0, v0, a0, j0;
} Data;

static double g_of(double v) {
  const double r = v / kVs;
  return kFc + (kFs - kFc) * exp(-r * r);
}

/* f_v and z' of the physical state. */
static void physics(double v, double z, double u, double* vdot, double* zdot) {
  const double g = g_of(v);
  *zdot = v - kS0 * fabs(v) * z / g;
  *vdot = (kThrustGain * u - kS0 * z - kS1 * *zdot - kS2 * v) / kMass;
}

/* d(vdot)/dv, d(vdot)/dz, d(zdot)/dv, d(zdot)/dz. */
static void physics_jac(double v, double z, double* a_vv, double* a_vz, double* a_zv, double* a_zz) {
  const double r = v / kVs;
  const double e = exp(-r * r);
  const double g = kFc + (kFs - kFc) * e;
  const double dg = -(kFs - kFc) * e * 2.0 * v / (kVs * kVs);
  const double sg = (v > 0.0) - (v < 0.0);
  *a_zv = 1.0 - kS0 * z * (sg * g - fabs(v) * dg) / (g * g);
  *a_zz = -kS0 * fabs(v) / g;
  *a_vv = -(kS1 * *a_zv + kS2) / kMass;
  *a_vz = -(kS0 + kS1 * *a_zz) / kMass;
}

static int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user) {
  const Data* d = (const Data*)user;
  const double* s = N_VGetArrayPointer(y);
  double* o = N_VGetArrayPointer(ydot);
  double v = s[1];
  if (d->deviation) {
    const double tau = t - d->t0;
    v += d->v0 + tau * (d->a0 + 0.5 * d->j0 * tau);
  }
  double vdot, zdot;
  physics(v, s[2], d->u, &vdot, &zdot);
  o[0] = s[1];
  o[1] = d->deviation ? vdot - d->a0 - d->j0 * (t - d->t0) : vdot;
  o[2] = zdot;
  return isfinite(o[1]) && isfinite(o[2]) ? 0 : 1;
}

static int jac(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix J, void* user, N_Vector t1, N_Vector t2, N_Vector t3) {
  (void)fy, (void)t1, (void)t2, (void)t3;
  const Data* d = (const Data*)user;
  const double* s = N_VGetArrayPointer(y);
  double v = s[1];
  if (d->deviation) {
    const double tau = t - d->t0;
    v += d->v0 + tau * (d->a0 + 0.5 * d->j0 * tau);
  }
  double a_vv, a_vz, a_zv, a_zz;
  physics_jac(v, s[2], &a_vv, &a_vz, &a_zv, &a_zz);
  SM_ELEMENT_D(J, 0, 0) = 0.0, SM_ELEMENT_D(J, 0, 1) = 1.0, SM_ELEMENT_D(J, 0, 2) = 0.0;
  SM_ELEMENT_D(J, 1, 0) = 0.0, SM_ELEMENT_D(J, 1, 1) = a_vv, SM_ELEMENT_D(J, 1, 2) = a_vz;
  SM_ELEMENT_D(J, 2, 0) = 0.0, SM_ELEMENT_D(J, 2, 1) = a_zv, SM_ELEMENT_D(J, 2, 2) = a_zz;
  return 0;
}

static void die(const char* what, int flag) {
  fprintf(stderr, "cvode-floor: %s failed (flag %d)\n", what, flag);
  exit(2);
}

/* The inputs u_k, one number per line of `path`; *n receives their count. NULL if the file
 * cannot be opened. */
static double* read_inputs(const char* path, size_t* n) {
  FILE* f = fopen(path, "r");
  if (!f) return NULL;
  size_t cap = 1 << 16;
  double* u = malloc(cap * sizeof *u);
  *n = 0;
  while (fscanf(f, "%lf", &u[*n]) == 1)
    if (++*n == cap) u = realloc(u, (cap *= 2) * sizeof *u);
  fclose(f);
  return u;
}

/* CVODE set up as plant/src/cvode_integrator.cpp (BDF or Adams, Newton, dense direct solver,
 * analytic Jacobian, rtol = 1e-8, atol = 1e-12 m, 1e-12 m/s, 1e-13 m), for the state y. */
typedef struct {
  SUNContext ctx;
  N_Vector y, atol;
  SUNMatrix A;
  SUNLinearSolver LS;
  void* mem;
} Solver;

static void solver_create(Solver* s, int adams, Data* data) {
  if (SUNContext_Create(NULL, &s->ctx)) die("SUNContext_Create", -1);
  s->y = N_VNew_Serial(3, s->ctx), s->atol = N_VNew_Serial(3, s->ctx);
  double* ya = N_VGetArrayPointer(s->y);
  double* aa = N_VGetArrayPointer(s->atol);
  aa[0] = 1e-12, aa[1] = 1e-12, aa[2] = 1e-13;
  ya[0] = ya[1] = ya[2] = 0.0;
  s->mem = CVodeCreate(adams ? CV_ADAMS : CV_BDF, s->ctx);
  int flag;
  if ((flag = CVodeInit(s->mem, rhs, 0.0, s->y))) die("CVodeInit", flag);
  CVodeSetUserData(s->mem, data);
  CVodeSVtolerances(s->mem, 1e-8, s->atol);
  s->A = SUNDenseMatrix(3, 3, s->ctx);
  s->LS = SUNLinSol_Dense(s->y, s->A, s->ctx);
  CVodeSetLinearSolver(s->mem, s->LS, s->A);
  CVodeSetJacFn(s->mem, jac);
  CVodeSetMaxNumSteps(s->mem, 100000);
}

static void solver_free(Solver* s) {
  CVodeFree(&s->mem);
  SUNLinSolFree(s->LS);
  SUNMatDestroy(s->A);
  N_VDestroy(s->y);
  N_VDestroy(s->atol);
  SUNContext_Free(&s->ctx);
}

/* One run over the n periods of length T from rest, u[k] held over [kT, (k+1)T] and CVODE
 * restarted at every period; prints the run's line (file comment). */
static void run_once(Solver* s, Data* data, const double* u, size_t n, double T, const char* form) {
  double* ya = N_VGetArrayPointer(s->y);
  const int deviation = data->deviation;
  double x = 0.0, v = 0.0, z = 0.0;
  long steps = 0, rhs_evals = 0, jac_evals = 0;
  struct timespec a, b, ca, cb;
  int flag;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ca);
  clock_gettime(CLOCK_MONOTONIC, &a);
  for (size_t k = 0; k < n; ++k) {
    const double t0 = (double)k * T, t1 = (double)(k + 1) * T;
    data->u = u[k];
    if (deviation) {
      double vdot, zdot, a_vv, a_vz, a_zv, a_zz;
      physics(v, z, u[k], &vdot, &zdot);
      physics_jac(v, z, &a_vv, &a_vz, &a_zv, &a_zz);
      data->t0 = t0, data->x0 = x, data->v0 = v, data->a0 = vdot, data->j0 = a_vv * vdot + a_vz * zdot;
      ya[0] = 0.0, ya[1] = 0.0, ya[2] = z;
    } else {
      ya[0] = x, ya[1] = v, ya[2] = z;
    }
    if ((flag = CVodeReInit(s->mem, t0, s->y))) die("CVodeReInit", flag);
    CVodeSetStopTime(s->mem, t1);
    sunrealtype t_reached;
    if ((flag = CVode(s->mem, t1, s->y, &t_reached, CV_NORMAL)) < 0) die("CVode", flag);
    long c;
    CVodeGetNumSteps(s->mem, &c), steps += c;
    CVodeGetNumRhsEvals(s->mem, &c), rhs_evals += c;
    CVodeGetNumJacEvals(s->mem, &c), jac_evals += c;
    if (deviation) {
      x = data->x0 + T * (data->v0 + T * (0.5 * data->a0 + T * data->j0 / 6.0)) + ya[0];
      v = data->v0 + T * (data->a0 + 0.5 * data->j0 * T) + ya[1];
    } else {
      x = ya[0], v = ya[1];
    }
    z = ya[2];
  }
  clock_gettime(CLOCK_MONOTONIC, &b);
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cb);
  const double sec = (double)(b.tv_sec - a.tv_sec) + 1e-9 * (double)(b.tv_nsec - a.tv_nsec);
  const double cpu = (double)(cb.tv_sec - ca.tv_sec) + 1e-9 * (double)(cb.tv_nsec - ca.tv_nsec);
  printf("%s seconds %.6f periods %zu steps %ld rhs %ld jac %ld x %.12g v %.12g z %.12g cpu %.6f\n", form, sec, n,
         steps, rhs_evals, jac_evals, x, v, z, cpu);
}

/* Reads the arguments (file comment), then REPEATS runs. */
int main(int argc, char** argv) {
  if (argc != 5) {
    fprintf(stderr, "usage: cvode-floor U_FILE PERIOD plain|deviation|adams REPEATS\n");
    return 2;
  }
  size_t n = 0;
  double* u = read_inputs(argv[1], &n);
  if (!u) {
    fprintf(stderr, "cvode-floor: cannot open %s\n", argv[1]);
    return 2;
  }
  const double T = atof(argv[2]);
  const int adams = strcmp(argv[3], "adams") == 0;
  const int deviation = adams || strcmp(argv[3], "deviation") == 0;
  if (!deviation && strcmp(argv[3], "plain") != 0) {
    fprintf(stderr, "cvode-floor: FORM %s is not plain, deviation or adams\n", argv[3]);
    return 2;
  }
  const int repeats = atoi(argv[4]);
  if (n == 0 || !(T > 0.0) || repeats < 1) {
    fprintf(stderr, "cvode-floor: no inputs in %s, or PERIOD/REPEATS not positive\n", argv[1]);
    return 2;
  }
  Data data = {0};
  data.deviation = deviation;
  Solver s;
  solver_create(&s, adams, &data);
  for (int r = 0; r < repeats; ++r) run_once(&s, &data, u, n, T, argv[3]);
  solver_free(&s);
  free(u);
  return 0;
}
