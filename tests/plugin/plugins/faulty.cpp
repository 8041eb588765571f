// Misbehaving controller plugins for tests/plugin/host_test.cpp, one shared library per fault
// (tests/CMakeLists.txt compiles this file once per FAULT_* definition):
//   FAULT_NONE      a proportional law u = gain*(xd - x), counts its updates (reset zeroes them)
//   FAULT_NAN       returns u = NaN at the third update
//   FAULT_THROW     throws a C++ exception out of update (what a plugin must not do)
//   FAULT_VERSION   reports ABI version 999
//   FAULT_OLD       reports ABI version 1 (a plugin built against the struct of model fields, before
//                   the key/value table of version 2)
//   FAULT_NO_RESET  does not export feeddrive_controller_reset
//   FAULT_REFUSE    create refuses, with a message
//   FAULT_FAIL      update fails at t >= 1e-3 s, with a message
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "feeddrive/controller/plugin.h"

namespace {
struct Law {
  double gain{1.0};
  long updates{0};
};
}  // namespace

extern "C" {

uint32_t feeddrive_controller_abi_version(void) {
#if defined(FAULT_VERSION)
  return 999;
#elif defined(FAULT_OLD)
  return 1;
#else
  return FEEDDRIVE_CONTROLLER_ABI_VERSION;
#endif
}

void* feeddrive_controller_create(const feeddrive_run_info* info, const feeddrive_parameter* params, size_t n,
                                  char* error, size_t size) {
#ifdef FAULT_REFUSE
  std::snprintf(error, size, "gain is required");
  (void)info, (void)params, (void)n;
  return nullptr;
#else
  if (info->size != sizeof(feeddrive_run_info)) return nullptr;
  Law* l = new Law;
  for (size_t i = 0; i < n; ++i) {
    if (std::strcmp(params[i].key, "gain") == 0) {
      l->gain = std::atof(params[i].value);
    } else {
      std::snprintf(error, size, "unknown parameter '%s'", params[i].key);
      delete l;
      return nullptr;
    }
  }
  return l;
#endif
}

int feeddrive_controller_update(void* self, const feeddrive_input* in, feeddrive_output* out, char* error,
                                size_t size) {
  Law* l = static_cast<Law*>(self);
  ++l->updates;
  out->u = l->gain * (in->xd - in->x);
  out->sliding = static_cast<double>(l->updates);  // the count, for the reset test
#ifdef FAULT_NAN
  if (l->updates == 3) out->u = std::numeric_limits<double>::quiet_NaN();
#endif
#ifdef FAULT_THROW
  if (l->updates == 2) throw std::runtime_error("boom");
#endif
#ifdef FAULT_FAIL
  if (in->t >= 1e-3) {
    std::snprintf(error, size, "position sensor lost");
    return 1;
  }
#endif
  (void)error, (void)size;
  return 0;
}

#ifndef FAULT_NO_RESET
void feeddrive_controller_reset(void* self) { static_cast<Law*>(self)->updates = 0; }
#endif

void feeddrive_controller_destroy(void* self) { delete static_cast<Law*>(self); }
}
