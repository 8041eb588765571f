/* An out-of-tree controller plugin (docs/plugins.md): the model-based sliding-mode law of Xie &
 * Liang (Sec. 5.2, eqs. 16-19) with a boundary layer, in plain C against feeddrive's plugin ABI
 * (feeddrive/controller/plugin.h) and nothing else of feeddrive.
 *
 *   e = xd - x,  S = de/dt + lambda*e,  reaching law dS/dt = -eta*sw(S) - k*S            (eq. 18)
 *   Ka*Kf*u*(1 - r(x)) = m*(xd'' + lambda*(xd' - x') + eta*sw(S) + k*S) + F^f + F^g + Fcog(x)
 *                                                                                     (eq. 19)
 * sw(S) = sat(S/phi) (default), tanh(S/phi) or sgn(S); F^f from the plant's true bristle state
 * (the paper's "all states available"): sigma0*z + sigma1(v)*zdot^ + sigma2*v with
 * zdot^ = (z_k - z_{k-1})/T (the model rate v - sigma0|v|z/g(v) at the first sample); F^g =
 * s(x)*Fg from the true Fg; the ripple from the nominal model. u saturated to [u_min, u_max].
 *
 * It computes every term in the same order as feeddrive's built-in sliding_mode controller
 * (controller/src/sliding_mode.cpp with friction_state/grinding_state: true, motion_state:
 * measured, no delay compensation), so both give the same commands bit for bit; CI checks it
 * (tests/service/plugin_test.sh).
 *
 * Parameters (scenario controller.parameters): eta [m/s^2] (5), k [1/s] (10), lambda [1/s] (50),
 * boundary_layer phi [m/s] (1e-3), switching sat|tanh|sgn (sat).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "feeddrive/controller/plugin.h"

#if defined(__GNUC__)
#define FD_EXPORT __attribute__((visibility("default")))
#else
#define FD_EXPORT
#endif

enum switching { SW_SAT, SW_TANH, SW_SGN };

typedef struct {
  feeddrive_run_info info;
  double eta, k, lambda, phi;
  enum switching sw;
  int has_last_z;
  double last_z;
} smc;

static void set_error(char* error, size_t size, const char* fmt, const char* a, const char* b) {
  if (error && size) snprintf(error, size, fmt, a, b);
}

/* Xie & Liang eq. 7 (Canudas de Wit 1995 eq. 3): g(v) = Fc + (Fs - Fc)*exp(-|v/vs|^delta). */
static double power(double r, double d) { return d == 2.0 ? r * r : d == 1.0 ? r : pow(r, d); }
static double stribeck(const feeddrive_model* m, double v) {
  const double r = fabs(v / m->stribeck_velocity);
  return m->coulomb_force + (m->static_force - m->coulomb_force) * exp(-power(r, m->stribeck_exponent));
}
static double micro_damping(const feeddrive_model* m, double v) {
  if (m->damping_decay_velocity <= 0.0) return m->bristle_damping;
  const double r = v / m->damping_decay_velocity;
  return m->bristle_damping * exp(-r * r);
}
static double lugre_zdot(const feeddrive_model* m, double v, double z) {
  return v - m->bristle_stiffness * fabs(v) * z / stribeck(m, v);
}
/* Ripple, Xie & Liang eqs. 14-15. */
static const double kTwoPi = 2.0 * M_PI;
static double cogging(const feeddrive_model* m, double x) {
  const double th = kTwoPi * x / m->pitch;
  return m->cogging_amplitude * sin(th + m->cogging_phase) + m->cogging_third * sin(3.0 * th + m->cogging_third_phase);
}
static double reluctance(const feeddrive_model* m, double x) {
  const double th = kTwoPi * x / m->pitch;
  return m->reluctance_amplitude * sin(th + m->reluctance_phase) +
         m->reluctance_third * sin(3.0 * th + m->reluctance_third_phase);
}
/* Grinding contact fraction s(x). */
static double contact_fraction(const feeddrive_model* m, double x) {
  if (!(x > m->contact_position)) return 0.0;
  if (m->contact_width <= 0.0) return 1.0;
  const double s = (x - m->contact_position) / m->contact_width;
  return s < 1.0 ? s : 1.0;
}

FD_EXPORT uint32_t feeddrive_controller_abi_version(void) { return FEEDDRIVE_CONTROLLER_ABI_VERSION; }

static int read_number(const feeddrive_parameter* p, double* out, char* error, size_t size) {
  char* end = NULL;
  const double v = strtod(p->value, &end);
  if (end == p->value || *end != '\0' || !isfinite(v)) {
    set_error(error, size, "parameter %s = '%s': not a number", p->key, p->value);
    return 0;
  }
  *out = v;
  return 1;
}

FD_EXPORT void* feeddrive_controller_create(const feeddrive_run_info* info, const feeddrive_parameter* params, size_t n,
                                            char* error, size_t size) {
  if (info->size != sizeof(feeddrive_run_info)) {
    set_error(error, size, "run info of a different layout%s%s (rebuild against this feeddrive)", "", "");
    return NULL;
  }
  smc c = {0};
  c.info = *info;
  c.eta = 5.0, c.k = 10.0, c.lambda = 50.0, c.phi = 1e-3, c.sw = SW_SAT;
  for (size_t i = 0; i < n; ++i) {
    const feeddrive_parameter* p = &params[i];
    int ok = 1;
    if (strcmp(p->key, "eta") == 0) ok = read_number(p, &c.eta, error, size);
    else if (strcmp(p->key, "k") == 0) ok = read_number(p, &c.k, error, size);
    else if (strcmp(p->key, "lambda") == 0) ok = read_number(p, &c.lambda, error, size);
    else if (strcmp(p->key, "boundary_layer") == 0) ok = read_number(p, &c.phi, error, size);
    else if (strcmp(p->key, "switching") == 0) {
      if (strcmp(p->value, "sat") == 0) c.sw = SW_SAT;
      else if (strcmp(p->value, "tanh") == 0) c.sw = SW_TANH;
      else if (strcmp(p->value, "sgn") == 0) c.sw = SW_SGN;
      else {
        set_error(error, size, "parameter %s = '%s': expected one of sat, tanh, sgn", p->key, p->value);
        return NULL;
      }
    } else {
      set_error(error, size, "unknown parameter '%s'%s (known: eta, k, lambda, boundary_layer, switching)", p->key, "");
      return NULL;
    }
    if (!ok) return NULL;
  }
  if (c.eta < 0.0 || c.k < 0.0 || !(c.lambda > 0.0) || (c.sw != SW_SGN && !(c.phi > 0.0))) {
    set_error(error, size, "eta, k must be >= 0, lambda and boundary_layer > 0%s%s", "", "");
    return NULL;
  }
  smc* self = malloc(sizeof *self);
  if (self == NULL) {
    set_error(error, size, "out of memory%s%s", "", "");
    return NULL;
  }
  *self = c;
  return self;
}

static double switching_function(const smc* c, double s) {
  switch (c->sw) {
    case SW_SAT: {
      const double q = s / c->phi;
      return q < -1.0 ? -1.0 : (1.0 < q ? 1.0 : q);
    }
    case SW_TANH: return tanh(s / c->phi);
    case SW_SGN: return (s > 0.0) - (s < 0.0);
  }
  return 0.0;
}

FD_EXPORT int feeddrive_controller_update(void* self, const feeddrive_input* in, feeddrive_output* out, char* error,
                                          size_t size) {
  smc* c = self;
  const feeddrive_model* m = &c->info.model;
  const int lugre = m->friction_model == FEEDDRIVE_FRICTION_LUGRE;
  if (!in->has_truth && (lugre || m->grinding_enabled)) {
    set_error(error, size, "this law uses the plant's true z and Fg%s%s, which this host does not send (hardware)", "",
              "");
    return 1;
  }
  const double x = in->x, v = in->v;
  double f_friction = 0.0;
  if (lugre) {
    const double z = in->z;
    const double zdot = c->has_last_z ? (z - c->last_z) / c->info.period : lugre_zdot(m, v, z);
    if (isfinite(z)) c->has_last_z = 1, c->last_z = z;
    f_friction = m->bristle_stiffness * z + micro_damping(m, v) * zdot + m->viscous * v;
    out->z_estimate = z;
  } else if (m->friction_model == FEEDDRIVE_FRICTION_STATIC) {
    f_friction = stribeck(m, v) * tanh(v / m->static_smoothing_velocity) + m->viscous * v;
    out->z_estimate = 0.0;
  }
  double f_grinding = 0.0;
  if (m->grinding_enabled) f_grinding = contact_fraction(m, x) * in->fg;
  double cog = 0.0, rel = 0.0;
  if (m->ripple_enabled) {
    cog = cogging(m, x);
    rel = reluctance(m, x);
  }
  const double e = in->xd - x;
  const double ed = in->vd - v;
  const double s = ed + c->lambda * e;
  const double a_cmd = in->ad + c->lambda * ed + c->eta * switching_function(c, s) + c->k * s;
  out->sliding = s;
  /* The built-in law's terms in its order; the observer disturbance and the model's additive
   * effects are 0 here (+ 0.0 keeps the sum's bits the same). */
  const double dc = 0.0, e0 = 0.0, e1 = 0.0;
  out->u_unsaturated =
      (m->mass * a_cmd + f_friction + f_grinding + cog + dc + e0) / (m->thrust_gain * (1.0 - rel - e1));
  const double u = out->u_unsaturated;
  out->u = isnan(u) ? 0.0 : u < c->info.u_min ? c->info.u_min : (c->info.u_max < u ? c->info.u_max : u);
  return 0;
}

FD_EXPORT void feeddrive_controller_reset(void* self) {
  smc* c = self;
  c->has_last_z = 0;
  c->last_z = 0.0;
}

FD_EXPORT void feeddrive_controller_destroy(void* self) { free(self); }
