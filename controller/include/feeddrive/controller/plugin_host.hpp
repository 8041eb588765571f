#pragma once
// The host side of the controller plugin ABI (feeddrive/controller/plugin.h, docs/plugins.md):
// a user's controller in a shared library, run as a Controller like the built-in ones, so
// feeddrive-sim, feeddrive-study and feeddrive-controller all run it.
//
// PluginLibrary opens the library once (dlopen, RTLD_NOW | RTLD_LOCAL), looks up the five
// symbols and checks the ABI version; PluginController is one instance of the plugin's law.
// Every failure is a PluginError (std::invalid_argument: the tools print it as one line and exit
// 2) that starts with "plugin <library>: " and names what failed: the file, the symbol, the
// version, the plugin's own message, a non-finite command, or an exception that left it.

#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "feeddrive/common/fields.hpp"
#include "feeddrive/controller/controller.hpp"
#include "feeddrive/controller/plugin.h"
#include "feeddrive/controller/quantity.hpp"
#include "feeddrive/plant/params.hpp"

namespace feeddrive::controller {

class PluginError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// What a run gives a plugin (scenario controller: {type: plugin, ...}).
struct PluginParams {
  std::string library;  ///< path of the shared library
  /// controller.parameters, as text, in the scenario's order.
  std::vector<std::pair<std::string, std::string>> parameters;
  plant::PlantParams model;       ///< the nominal model (controller.model; defaults to the plant)
  double period{1e-4};            ///< T [s]
  double u_min{-10.0};            ///< [V]
  double u_max{10.0};             ///< [V]
  double computation_delay{0.0};  ///< [s]
  /// The scenario keys of type plugin with one value (controller.*); `parameters` (a map of the
  /// plugin's own names) and `model` (the plant's list) are read by rules of their own, period and
  /// computation_delay come from the scenario.
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(library).required().doc(
        "the plugin's shared library, relative to the scenario's folder; opened when the scenario is loaded "
        "(file, the five symbols, the ABI version)"));
    a->Visit(quantity::u_min(u_min));
    a->Visit(quantity::u_max(u_max));
  }
  void validate(const std::string& prefix = "controller") const;
};

/// An opened plugin library with its symbols resolved and its ABI version checked. Shared by
/// every instance created from it (the library stays loaded while one exists).
class PluginLibrary {
 public:
  /// Throws PluginError: missing file or not loadable, missing symbol, ABI version mismatch.
  static std::shared_ptr<const PluginLibrary> open(const std::string& path);
  ~PluginLibrary();
  PluginLibrary(const PluginLibrary&) = delete;
  PluginLibrary& operator=(const PluginLibrary&) = delete;

  const std::string& path() const { return path_; }
  feeddrive_controller_create_fn create{nullptr};
  feeddrive_controller_update_fn update{nullptr};
  feeddrive_controller_reset_fn reset{nullptr};
  feeddrive_controller_destroy_fn destroy{nullptr};

 private:
  explicit PluginLibrary(std::string path) : path_(std::move(path)) {}
  std::string path_;
  void* handle_{nullptr};
};

/// The run information the host passes to create() (plugin.h feeddrive_run_info), with the
/// storage its model table points into: the nominal model's plant::parameter_table (the plant's
/// one list, walked). Valid while this object lives (a PluginController keeps it until destroy);
/// not copyable, as the table points into it.
class PluginRunInfo {
 public:
  explicit PluginRunInfo(const PluginParams& p);
  PluginRunInfo(const PluginRunInfo&) = delete;
  PluginRunInfo& operator=(const PluginRunInfo&) = delete;
  const feeddrive_run_info& info() const { return info_; }

 private:
  std::vector<fields::FlatValue> values_;
  std::vector<feeddrive_value> table_;
  feeddrive_run_info info_{};
};

class PluginController final : public Controller {
 public:
  /// Opens the library (or reuses `library` if given) and creates one instance; throws
  /// PluginError with the plugin's own message if create() refuses.
  explicit PluginController(const PluginParams& p, std::shared_ptr<const PluginLibrary> library = nullptr);
  ~PluginController() override;
  PluginController(const PluginController&) = delete;
  PluginController& operator=(const PluginController&) = delete;

  /// Throws PluginError if update() fails, throws, or returns a non-finite u.
  Command update(const trajectory::Sample& ref, const plant::Measurement& meas, const Truth* truth) override;
  std::string name() const override { return "plugin"; }
  /// Back to the state create() left (plugin.h feeddrive_controller_reset).
  void reset();

 private:
  [[noreturn]] void fail(const std::string& what) const;
  std::shared_ptr<const PluginLibrary> lib_;
  PluginRunInfo run_info_;  // what create() was given: the plugin may keep pointers into it until destroy
  void* self_{nullptr};
};

}  // namespace feeddrive::controller
