#pragma once
// Every params list of a scenario, in one place: the list's table name in docs/scenario.md, the
// key prefix of its keys and a default of its struct. The key tables and their units
// (key_tables.cpp) and the old spellings' respelling (canonical_key, scenario_set.cpp) walk this
// one registry, so a list added here has its table, its units and its aliases everywhere.

#include <string>

#include "feeddrive/common/fields.hpp"
#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::sim::detail {

/// The plant without its effects (the effects have a table of their own).
struct PlantSections {
  plant::PlantParams p;
  template <class Archive>
  void Serialize(Archive* a) {
    Filter<Archive> f{a};
    p.Serialize(&f);
  }
  template <class Archive>
  struct Filter {
    Archive* a;
    template <typename T>
    void Visit(const fields::Field<T>& f) {
      if (std::string(f.meta.name) != "effects") a->Visit(f);
    }
  };
};

/// Calls f(table_name, key_prefix, list) for every list, in document order. key_prefix is ""
/// for the top level; a controller's or a reference's type has its section's prefix (its keys
/// are controller.<key>, reference.<key>). A controller's model (controller.model) is the plant's
/// list under another prefix (plant_prefixes).
template <typename F>
void for_each_list(F&& f) {
  f("scenario", "", Scenario{});
  f("plant", "plant", PlantSections{});
  f("plant.effects", "plant.effects", plant::EffectsParams{});
  f("controller", "controller", ControllerConfig{});
  f("controller.sliding_mode", "controller", controller::SlidingModeParams{});
  f("controller.cascade", "controller", controller::CascadeParams{});
  f("controller.open_loop", "controller", controller::OpenLoopParams{});
  f("controller.plugin", "controller", controller::PluginParams{});
  f("reference", "reference", ReferenceConfig{});
  f("reference.sine", "reference", trajectory::SineParams{});
  f("reference.step", "reference", trajectory::StepParams{});
  f("reference.accel_limited", "reference", trajectory::AccelLimitedParams{});
  f("reference.scurve", "reference", trajectory::SCurveParams{});
  f("reference.ramp", "reference", trajectory::RampParams{});
}

/// The prefixes the plant's list has: the plant's own and a controller's nominal model.
inline const char* const kPlantPrefixes[] = {"plant", "controller.model"};

/// `prefix.key`, or `key` at the top level (prefix "").
inline std::string dotted(const std::string& prefix, const std::string& key) {
  return prefix.empty() ? key : prefix + "." + key;
}

}  // namespace feeddrive::sim::detail
