#include "feeddrive/controller/plugin_host.hpp"

#include <dlfcn.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include "check.hpp"
#include "feeddrive/plant/parameter_table.hpp"

namespace feeddrive::controller {
namespace {

constexpr std::size_t kErrorSize = 512;

std::string message_of(const char* buf) {
  std::string m(buf);
  for (char& c : m)
    if (c == '\n' || c == '\r') c = ' ';  // one line
  return m.empty() ? "(no message)" : m;
}

}  // namespace

void PluginParams::validate(const std::string& prefix) const {
  using namespace detail;
  if (library.empty())
    throw std::invalid_argument(prefix + ".library = '': needs the path of the plugin's shared library");
  require_positive(prefix + ".period", period);
  require_range(prefix, u_min, u_max);
  require_non_negative(prefix + ".computation_delay", computation_delay);
  model.validate(prefix + ".model");
}

std::shared_ptr<const PluginLibrary> PluginLibrary::open(const std::string& path) {
  const std::string where = "plugin " + path + ": ";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw PluginError(where + "no such file (controller.library names the plugin's shared library)");
  std::shared_ptr<PluginLibrary> lib(new PluginLibrary(path));
  // A path without a slash would make dlopen search the library path instead of this file.
  const std::string open_path = path.find('/') == std::string::npos ? "./" + path : path;
  lib->handle_ = dlopen(open_path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (lib->handle_ == nullptr) {
    const char* e = dlerror();
    throw PluginError(where + "cannot be loaded: " + (e ? message_of(e) : "dlopen failed"));
  }
  const auto symbol = [&](const char* name) {
    dlerror();
    void* s = dlsym(lib->handle_, name);
    if (s == nullptr)
      throw PluginError(where + "missing symbol " + name +
                        " (plugin.h: a plugin exports all five functions with C linkage)");
    return s;
  };
  const auto version =
      reinterpret_cast<feeddrive_controller_abi_version_fn>(symbol("feeddrive_controller_abi_version"));
  lib->create = reinterpret_cast<feeddrive_controller_create_fn>(symbol("feeddrive_controller_create"));
  lib->update = reinterpret_cast<feeddrive_controller_update_fn>(symbol("feeddrive_controller_update"));
  lib->reset = reinterpret_cast<feeddrive_controller_reset_fn>(symbol("feeddrive_controller_reset"));
  lib->destroy = reinterpret_cast<feeddrive_controller_destroy_fn>(symbol("feeddrive_controller_destroy"));
  const std::uint32_t v = version();
  if (v != FEEDDRIVE_CONTROLLER_ABI_VERSION)
    throw PluginError(where + "ABI version " + std::to_string(v) + ", this feeddrive hosts ABI version " +
                      std::to_string(FEEDDRIVE_CONTROLLER_ABI_VERSION) +
                      " only (rebuild the plugin against this feeddrive's plugin.h; docs/plugins.md)");
  return lib;
}

PluginLibrary::~PluginLibrary() {
  if (handle_) dlclose(handle_);
}

PluginRunInfo::PluginRunInfo(const PluginParams& p) : values_(plant::parameter_table(p.model)) {
  table_.reserve(values_.size());
  for (const fields::FlatValue& v : values_) table_.push_back({v.key.c_str(), v.number, v.name.c_str()});
  info_.abi_version = FEEDDRIVE_CONTROLLER_ABI_VERSION;
  info_.size = sizeof(feeddrive_run_info);
  info_.period = p.period;
  info_.u_min = p.u_min;
  info_.u_max = p.u_max;
  info_.computation_delay = p.computation_delay;
  info_.model = table_.data();
  info_.model_size = table_.size();
}

PluginController::PluginController(const PluginParams& p, std::shared_ptr<const PluginLibrary> library)
    : lib_(library ? std::move(library) : PluginLibrary::open(p.library)), run_info_(p) {
  p.validate("controller");
  const feeddrive_run_info& info = run_info_.info();
  std::vector<feeddrive_parameter> params;
  params.reserve(p.parameters.size());
  for (const auto& [k, v] : p.parameters) params.push_back({k.c_str(), v.c_str()});
  char error[kErrorSize] = {0};
  try {
    self_ = lib_->create(&info, params.data(), params.size(), error, sizeof error);
  } catch (...) {
    fail("create: an exception left the plugin (plugin.h: a plugin reports errors by its return value)");
  }
  if (self_ == nullptr) fail("create refused: " + message_of(error));
}

PluginController::~PluginController() {
  if (self_) lib_->destroy(self_);
}

void PluginController::fail(const std::string& what) const {
  throw PluginError("plugin " + lib_->path() + ": " + what);
}

void PluginController::reset() {
  try {
    lib_->reset(self_);
  } catch (...) {
    fail("reset: an exception left the plugin");
  }
}

Command PluginController::update(const trajectory::Sample& ref, const plant::Measurement& meas, const Truth* truth) {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  feeddrive_input in{};
  in.size = sizeof in;
  in.t = meas.t;
  in.xd = ref.position;
  in.vd = ref.velocity;
  in.ad = ref.acceleration;
  in.jd = ref.jerk;
  in.x = meas.x;
  in.v = meas.v;
  in.has_truth = truth != nullptr;
  in.z = truth ? truth->z : nan;
  in.fg = truth ? truth->fg : nan;
  feeddrive_output out{nan, nan, nan, nan};
  char error[kErrorSize] = {0};
  int rc = 0;
  try {
    rc = lib_->update(self_, &in, &out, error, sizeof error);
  } catch (...) {
    fail("update at t = " + validate::format_number(meas.t) + " s: an exception left the plugin");
  }
  if (rc != 0) fail("update at t = " + validate::format_number(meas.t) + " s failed: " + message_of(error));
  if (!std::isfinite(out.u))
    fail("update at t = " + validate::format_number(meas.t) + " s returned u = " + validate::format_number(out.u) +
         " (a command must be a finite number)");
  Command c;
  c.u = out.u;
  c.u_unsaturated = out.u_unsaturated;
  c.sliding = out.sliding;
  c.z_estimate = out.z_estimate;
  return c;
}

}  // namespace feeddrive::controller
