/* feeddrive controller plugin ABI, version 2 (docs/plugins.md).
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
 * was compiled against the same layout the host fills. Version 2 (issue 22) replaced version 1's
 * struct of model fields (a copy of the plant's list that missed friction.static_smoothing_shape)
 * by the key/value table of feeddrive_run_info.model.
 *
 * Units are SI: m, m/s, m/s^2, N, kg, s, V.
 */
#ifndef FEEDDRIVE_CONTROLLER_PLUGIN_H
#define FEEDDRIVE_CONTROLLER_PLUGIN_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

#define FEEDDRIVE_CONTROLLER_ABI_VERSION 2u

/* One value of the controller's nominal model (feeddrive_run_info.model). */
typedef struct feeddrive_value {
  const char* key;  /* the scenario's key below controller.model: "mass", "friction.stribeck_exponent" */
  double number;    /* a number [SI unit of the key, docs/scenario.md]; a flag 1 or 0; NaN for a name */
  const char* name; /* an enum's name ("lugre", "static", "none" for friction.model); "" for a number */
} feeddrive_value;

/* What a run tells the plugin when it creates it. */
typedef struct feeddrive_run_info {
  uint32_t abi_version;     /* the host's FEEDDRIVE_CONTROLLER_ABI_VERSION */
  uint32_t size;            /* sizeof(feeddrive_run_info) as the host was compiled */
  double period;            /* control period T [s] */
  double u_min, u_max;      /* command limits [V] (scenario controller.u_min, u_max) */
  double computation_delay; /* [s]: the command computed at t_k acts from t_k + delay */
  /* The nominal model (the scenario's controller.model, which defaults to the plant without its
   * effects): every key of the plant's parameter list (plant/params.hpp; the tables of
   * docs/scenario.md, "plant") by its key below plant:, in the list's order, except the sections
   * effects (off in a plugin's model) and integrator (the simulator's tolerances); then two
   * derived values: "thrust_gain" Ka*Kf [N/V] and "grinding.damping" C = c*pi*dw*bs [N s/m].
   * Read it with feeddrive_model_number / feeddrive_model_name below. A key added to the list
   * appears here without an ABI change. The table and its strings stay valid until destroy. */
  const feeddrive_value* model;
  size_t model_size;
} feeddrive_run_info;

/* The number of the model's key `key` into *out: 1, or 0 (and *out unchanged) when the model has
 * no such key or it is a name. */
static inline int feeddrive_model_number(const feeddrive_run_info* info, const char* key, double* out) {
  size_t i;
  for (i = 0; i < info->model_size; ++i) {
    if (strcmp(info->model[i].key, key) != 0) continue;
    if (info->model[i].name[0] != '\0') return 0;
    *out = info->model[i].number;
    return 1;
  }
  return 0;
}

/* The name of the model's key `key` (friction.model: "lugre", "static" or "none"), or NULL when
 * the model has no such key or it is a number. */
static inline const char* feeddrive_model_name(const feeddrive_run_info* info, const char* key) {
  size_t i;
  for (i = 0; i < info->model_size; ++i)
    if (strcmp(info->model[i].key, key) == 0) return info->model[i].name[0] != '\0' ? info->model[i].name : NULL;
  return NULL;
}

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
