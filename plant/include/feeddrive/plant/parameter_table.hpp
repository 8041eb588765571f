#pragma once
// The drive's parameters as a table of (key, value) for the readers that are not C++: the
// controller plugin ABI (controller/plugin.h, feeddrive_run_info.model) and the run's
// self-description on LCM (lcmtypes/run_info_t.lcm, run_info_t.plant). The table is PlantParams'
// list (params.hpp) walked by fields::flatten, so a field added to the list reaches every plugin
// and every participant without further code; the keys are the scenario's keys below `plant:`
// (or `controller.model:`), "friction.stribeck_exponent", in the list's order.

#include <string>
#include <vector>

#include "feeddrive/common/fields.hpp"
#include "feeddrive/plant/params.hpp"

namespace feeddrive::plant {

/// What a table leaves out of the list, with everything below: the model-discrepancy effects
/// (the hidden difference between a drive and its nominal model, docs/fit.md: a controller is
/// not told them) and the integrator's tolerances (the simulator's numerics, not the drive).
inline const std::vector<std::string>& table_excluded_keys() {
  static const std::vector<std::string> k = {"effects", "integrator"};
  return k;
}

/// The values a table adds after the list's, derived from it (none is a key of the list; a test
/// checks it): "thrust_gain" Ka*Kf [N/V] (PlantParams::thrust_gain) and "grinding.damping"
/// C = c*pi*dw*bs [N*s/m] (GrindingParams::damping).
inline const std::vector<std::string>& table_derived_keys() {
  static const std::vector<std::string> k = {"thrust_gain", "grinding.damping"};
  return k;
}

/// The table of `p`: every key of its list but table_excluded_keys(), then the derived values.
/// A flag is 1 or 0, an enum its name (number NaN).
std::vector<fields::FlatValue> parameter_table(const PlantParams& p);

}  // namespace feeddrive::plant
