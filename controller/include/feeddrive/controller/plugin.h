/* feeddrive controller plugin ABI, version 1 (docs/plugins.md).
 *
 * A controller plugin is a shared library (a .so) that exports the five functions below with C
 * linkage, so it can be written in C, C++, Rust, Fortran (bind(C)) or any language with a C FFI.
 * The same library runs in-process in feeddrive-sim and feeddrive-study (scenario key
 * `controller: {type: plugin, library: PATH, parameters: {...}}`) and as an LCM participant
 * (`feeddrive-controller --plugin PATH`).
 *
 * Call sequence, per instance (one instance per run; a host may hold many at once, on several
 * threads, so a plugin keeps all its state in its instance and none in globals):
 *   feeddrive_controller_abi_version()        must return FEEDDRIVE_CONTROLLER_ABI_VERSION
 *   self = feeddrive_controller_create(info, params, n, err, size)
 *   once per control period, in time order:
 *     feeddrive_controller_update(self, in, out, err, size)
 *   feeddrive_controller_reset(self)           back to the state create() left (a new run)
 *   feeddrive_controller_destroy(self)
 * The host never calls one instance from two threads at once.
 *
 * Errors: create returns NULL and update returns non-zero, with a one-line message written
 * (NUL-terminated, truncated to error_size) into `error`; the host stops the run and prints
 * "plugin <library>: <message>" (exit 2). A plugin must not let an exception or a panic cross
 * these functions; the host also refuses a non-finite command u.
 *
 * Versioning rule: FEEDDRIVE_CONTROLLER_ABI_VERSION is one integer. Any change to a struct below
 * (a field added, removed, reordered or retyped) or to a function's signature or meaning
 * increments it; the host loads only a plugin whose feeddrive_controller_abi_version() returns
 * exactly the host's version, and names both otherwise. `size` fields let a plugin check that it
 * was compiled against the same layout the host fills.
 *
 * Units are SI: m, m/s, m/s^2, N, kg, s, V.
 */
#ifndef FEEDDRIVE_CONTROLLER_PLUGIN_H
#define FEEDDRIVE_CONTROLLER_PLUGIN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define FEEDDRIVE_CONTROLLER_ABI_VERSION 1u

/* The friction law of the nominal model (plant/params.hpp FrictionModel). */
enum feeddrive_friction_model {
  FEEDDRIVE_FRICTION_LUGRE = 0,
  FEEDDRIVE_FRICTION_STATIC = 1,
  FEEDDRIVE_FRICTION_NONE = 2
};

/* The controller's nominal model of the drive (the scenario's controller.model, which defaults
 * to the plant without its effects): the fields of plant/params.hpp, same names and units. */
typedef struct feeddrive_model {
  double mass;           /* m [kg] */
  double thrust_gain;    /* Ka*Kf [N/V] (amplifier_gain * force_constant) */
  double amplifier_gain; /* Ka */
  double force_constant; /* Kf [N/A] */
  /* friction: F = sigma0*z + sigma1(v)*z' + sigma2*v (LuGre) or g(v)*tanh(v/eps) + sigma2*v (static) */
  int32_t friction_model;           /* enum feeddrive_friction_model */
  double static_force;              /* Fs [N] */
  double coulomb_force;             /* Fc [N] */
  double stribeck_velocity;         /* vs [m/s] */
  double stribeck_exponent;         /* delta */
  double bristle_stiffness;         /* sigma0 [N/m] */
  double bristle_damping;           /* sigma1 [N s/m] */
  double viscous;                   /* sigma2 [N s/m] */
  double damping_decay_velocity;    /* vd [m/s], 0 = constant sigma1 */
  double static_smoothing_velocity; /* eps [m/s] */
  /* ripple (Xie & Liang eqs. 14-15) */
  int32_t ripple_enabled;
  double pitch, cogging_amplitude, cogging_phase, cogging_third, cogging_third_phase;
  double reluctance_amplitude, reluctance_phase, reluctance_third, reluctance_third_phase;
  /* grinding (Hahn-Lindsay, eq. 13): force s(x)*Fg, s(x) = clamp((x - contact_position)/contact_width, 0, 1) */
  int32_t grinding_enabled;
  double grinding_stiffness; /* ke [N/m] */
  double grinding_damping;   /* C = c*pi*dw*bs [N s/m] */
  double contact_position;   /* [m], -inf = always in contact */
  double contact_width;      /* [m] */
  /* encoder */
  double sensor_quantization; /* q [m], 0 = ideal */
} feeddrive_model;

/* What a run tells the plugin when it creates it. */
typedef struct feeddrive_run_info {
  uint32_t abi_version;     /* the host's FEEDDRIVE_CONTROLLER_ABI_VERSION */
  uint32_t size;            /* sizeof(feeddrive_run_info) as the host was compiled */
  double period;            /* control period T [s] */
  double u_min, u_max;      /* command limits [V] (scenario controller.u_min, u_max) */
  double computation_delay; /* [s]: the command computed at t_k acts from t_k + delay */
  feeddrive_model model;    /* the nominal model */
} feeddrive_run_info;

/* One user parameter: the scenario's controller.parameters entry as text ("5e-4", "sat"). */
typedef struct feeddrive_parameter {
  const char* key;
  const char* value;
} feeddrive_parameter;

/* The input of one control period (sample instant t). */
typedef struct feeddrive_input {
  uint32_t size;         /* sizeof(feeddrive_input) */
  double t;              /* [s] */
  double xd, vd, ad, jd; /* reference: position, velocity, acceleration, jerk */
  double x, v;           /* measured position and velocity */
  int32_t has_truth;     /* 1 in simulation: z and fg are the plant's true states */
  double z;              /* LuGre bristle deflection [m] (NaN without truth) */
  double fg;             /* grinding force state [N] (NaN without truth) */
} feeddrive_input;

/* The output. The host fills the diagnostics with NaN before each call. */
typedef struct feeddrive_output {
  double u;             /* command [V], applied as given (saturate it yourself) */
  double u_unsaturated; /* diagnostic: before saturation [V] */
  double sliding;       /* diagnostic: sliding variable S [m/s] */
  double z_estimate;    /* diagnostic: bristle state used by the law [m] */
} feeddrive_output;

/* The five exported functions (their names are the ABI; the typedefs are for hosts). */
uint32_t feeddrive_controller_abi_version(void);
void* feeddrive_controller_create(const feeddrive_run_info* info, const feeddrive_parameter* params, size_t n_params,
                                  char* error, size_t error_size);
int feeddrive_controller_update(void* self, const feeddrive_input* in, feeddrive_output* out, char* error,
                                size_t error_size);
void feeddrive_controller_reset(void* self);
void feeddrive_controller_destroy(void* self);

typedef uint32_t (*feeddrive_controller_abi_version_fn)(void);
typedef void* (*feeddrive_controller_create_fn)(const feeddrive_run_info*, const feeddrive_parameter*, size_t, char*,
                                                size_t);
typedef int (*feeddrive_controller_update_fn)(void*, const feeddrive_input*, feeddrive_output*, char*, size_t);
typedef void (*feeddrive_controller_reset_fn)(void*);
typedef void (*feeddrive_controller_destroy_fn)(void*);

#ifdef __cplusplus
}
#endif

#endif /* FEEDDRIVE_CONTROLLER_PLUGIN_H */
