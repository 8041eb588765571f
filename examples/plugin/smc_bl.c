/* An out-of-tree controller plugin (docs/plugins.md): the model-based sliding-mode law of Xie &
 * Liang (Sec. 5.2, eqs. 16-19) with a boundary layer, in plain C against feeddrive's plugin ABI
 * (feeddrive/controller/plugin.h) and nothing else of feeddrive.
 *
 *   e = xd - x,  S = de/dt + lambda*e,  reaching law dS/dt = -eta*sw(S) - k*S            (eq. 18)
 *   Ka*Kf*u*(1 - r(x)) = m*(xd'' + lambda*(xd' - x') + eta*sw(S) + k*S) + F^f + F^g + Fcog(x)
 *                                                                                     (eq. 19)
 * sw(S) = sat(S/phi) (default), tanh(S/phi) or sgn(S); F^f from the plant's true bristle state
 * (the paper's "all states available"): sigma0*z + sigma1(v)*zdot^ + sigma2*v with
 * zdot^ = (z_k - z_{k-1})/T (the model rate v - sigma0|v|z/g(v) at the first sample), or the
 * static map g(v)*sgn_eps(v) + sigma2*v; F^g = s(x)*Fg from the true Fg; the ripple from the
 * nominal model, read from the host's table by key (read_model). u saturated to [u_min, u_max].
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
enum friction { FR_LUGRE, FR_STATIC, FR_NONE };

/* The law's nominal model: what it reads of the host's model table (plugin.h, feeddrive_run_info.model). */
typedef struct {
  enum friction friction;
  int ripple_enabled, grinding_enabled;
  double mass, thrust_gain;
  double static_force, coulomb_force, stribeck_velocity, stribeck_exponent, bristle_stiffness, bristle_damping, viscous;
  double damping_decay_velocity, static_smoothing_velocity, static_smoothing_shape;
  double pitch, cogging_amplitude, cogging_phase, cogging_third, cogging_third_phase;
  double reluctance_amplitude, reluctance_phase, reluctance_third, reluctance_third_phase;
  double contact_position, contact_width;
} model;

typedef struct {
  model m;
  double period, u_min, u_max;
  double eta, k, lambda, phi;
  enum switching sw;
  int has_last_z;
  double last_z;
} smc;

static void set_error(char* error, size_t size, const char* fmt, const char* a, const char* b) {
  if (error && size) snprintf(error, size, fmt, a, b);
}

/* The model from the host's table, by the scenario's keys; a key the table lacks is an error
 * naming it (a host of another feeddrive). */
static int read_model(const feeddrive_run_info* info, model* m, char* error, size_t size) {
  double ripple = 0.0, grinding = 0.0;
  const struct {
    const char* key;
    double* to;
  } numbers[] = {
      {"mass", &m->mass},
      {"thrust_gain", &m->thrust_gain},
      {"friction.static_force", &m->static_force},
      {"friction.coulomb_force", &m->coulomb_force},
      {"friction.stribeck_velocity", &m->stribeck_velocity},
      {"friction.stribeck_exponent", &m->stribeck_exponent},
      {"friction.bristle_stiffness", &m->bristle_stiffness},
      {"friction.bristle_damping", &m->bristle_damping},
      {"friction.viscous", &m->viscous},
      {"friction.damping_decay_velocity", &m->damping_decay_velocity},
      {"friction.static_smoothing_velocity", &m->static_smoothing_velocity},
      {"friction.static_smoothing_shape", &m->static_smoothing_shape},
      {"ripple.enabled", &ripple},
      {"ripple.pitch", &m->pitch},
      {"ripple.cogging_amplitude", &m->cogging_amplitude},
      {"ripple.cogging_phase", &m->cogging_phase},
      {"ripple.cogging_third", &m->cogging_third},
      {"ripple.cogging_third_phase", &m->cogging_third_phase},
      {"ripple.reluctance_amplitude", &m->reluctance_amplitude},
      {"ripple.reluctance_phase", &m->reluctance_phase},
      {"ripple.reluctance_third", &m->reluctance_third},
      {"ripple.reluctance_third_phase", &m->reluctance_third_phase},
      {"grinding.enabled", &grinding},
      {"grinding.contact_position", &m->contact_position},
      {"grinding.contact_width", &m->contact_width},
  };
  for (size_t i = 0; i < sizeof numbers / sizeof numbers[0]; ++i) {
    if (!feeddrive_model_number(info, numbers[i].key, numbers[i].to)) {
      set_error(error, size, "the host's model has no number %s%s (plugin.h, feeddrive_run_info.model)", numbers[i].key,
                "");
      return 0;
    }
  }
  m->ripple_enabled = ripple != 0.0;
  m->grinding_enabled = grinding != 0.0;
  const char* law = feeddrive_model_name(info, "friction.model");
  if (law == NULL) {
    set_error(error, size, "the host's model has no name friction.model%s%s", "", "");
    return 0;
  }
  if (strcmp(law, "lugre") == 0) m->friction = FR_LUGRE;
  else if (strcmp(law, "static") == 0) m->friction = FR_STATIC;
  else if (strcmp(law, "none") == 0) m->friction = FR_NONE;
  else {
    set_error(error, size, "friction.model = '%s': expected lugre, static or none%s", law, "");
    return 0;
  }
  return 1;
}

/* Xie & Liang eq. 7 (Canudas de Wit 1995 eq. 3): g(v) = Fc + (Fs - Fc)*exp(-|v/vs|^delta). */
static double power(double r, double d) { return d == 2.0 ? r * r : d == 1.0 ? r : pow(r, d); }
static double stribeck(const model* m, double v) {
  const double r = fabs(v / m->stribeck_velocity);
  return m->coulomb_force + (m->static_force - m->coulomb_force) * exp(-power(r, m->stribeck_exponent));
}
/* The smoothed sign of the static model (plant/forces.hpp, smoothed_sign): with b the shape,
 * (1 - b)*tanh(v/eps) + b*v/sqrt(v^2 + eps^2). */
static double smoothed_sign(const model* m, double v) {
  const double eps = m->static_smoothing_velocity, b = m->static_smoothing_shape;
  const double th = tanh(v / eps);
  return b == 0.0 ? th : (1.0 - b) * th + b * v / sqrt(v * v + eps * eps);
}
static double micro_damping(const model* m, double v) {
  if (m->damping_decay_velocity <= 0.0) return m->bristle_damping;
  const double r = v / m->damping_decay_velocity;
  return m->bristle_damping * exp(-r * r);
}
static double lugre_zdot(const model* m, double v, double z) {
  return v - m->bristle_stiffness * fabs(v) * z / stribeck(m, v);
}
/* Ripple, Xie & Liang eqs. 14-15. */
static const double kTwoPi = 2.0 * M_PI;
static double cogging(const model* m, double x) {
  const double th = kTwoPi * x / m->pitch;
  return m->cogging_amplitude * sin(th + m->cogging_phase) + m->cogging_third * sin(3.0 * th + m->cogging_third_phase);
}
static double reluctance(const model* m, double x) {
  const double th = kTwoPi * x / m->pitch;
  return m->reluctance_amplitude * sin(th + m->reluctance_phase) +
         m->reluctance_third * sin(3.0 * th + m->reluctance_third_phase);
}
/* Grinding contact fraction s(x). */
static double contact_fraction(const model* m, double x) {
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
  if (!read_model(info, &c.m, error, size)) return NULL;
  c.period = info->period, c.u_min = info->u_min, c.u_max = info->u_max;
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
  const model* m = &c->m;
  const int lugre = m->friction == FR_LUGRE;
  if (!in->has_truth && (lugre || m->grinding_enabled)) {
    set_error(error, size, "this law uses the plant's true z and Fg%s%s, which this host does not send (hardware)", "",
              "");
    return 1;
  }
  const double x = in->x, v = in->v;
  double f_friction = 0.0;
  if (lugre) {
    const double z = in->z;
    const double zdot = c->has_last_z ? (z - c->last_z) / c->period : lugre_zdot(m, v, z);
    if (isfinite(z)) c->has_last_z = 1, c->last_z = z;
    f_friction = m->bristle_stiffness * z + micro_damping(m, v) * zdot + m->viscous * v;
    out->z_estimate = z;
  } else if (m->friction == FR_STATIC) {
    f_friction = stribeck(m, v) * smoothed_sign(m, v) + m->viscous * v;
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
  out->u = isnan(u) ? 0.0 : u < c->u_min ? c->u_min : (c->u_max < u ? c->u_max : u);
  return 0;
}

FD_EXPORT void feeddrive_controller_reset(void* self) {
  smc* c = self;
  c->has_last_z = 0;
  c->last_z = 0.0;
}

FD_EXPORT void feeddrive_controller_destroy(void* self) { free(self); }
