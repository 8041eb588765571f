#pragma once
// The controllers' shared quantities, declared once (the plant's `namespace quantity` style,
// plant/params.hpp): every controller params struct lists them through these, so a quantity has
// one name, unit, rule, plausible range and meaning in every list (docs/contributing.md).

#include "feeddrive/common/fields.hpp"

namespace feeddrive::controller::quantity {

using fields::field;
using fields::Field;

/// The output saturation [V], lower and upper: finite, u_min < u_max (validate()'s require_range).
inline Field<double> u_min(double& v) {
  return field("u_min", v).unit("V").unchecked().plausible(-1000, 1000).doc("output saturation, lower; < u_max");
}
inline Field<double> u_max(double& v) { return u_min(v).with_name("u_max").doc("output saturation, upper; > u_min"); }

/// gamma [1/s] of the feedforward adaptation (feedforward_adaptation.hpp); what it needs of the
/// controller's other keys is checked, and named, by its validate().
inline Field<double> adaptation_rate(double& v) {
  return field("adaptation_rate", v)
      .unit("1/s")
      .non_negative()
      .plausible(0, 200)
      .doc(
          "rate of the friction and inertia feedforward adapted from the disturbance estimate (needs the "
          "controller's observer: validate() names the keys); 0: off; must be < 2/control_period (stability of "
          "the normalised update); above 200 warns: gamma = 1000 gave 9.38 um vs 1.57 um without adaptation on the "
          "sine with Fs, Fc x0.5 (docs/controllers.md; measured 20 to 100)");
}

}  // namespace feeddrive::controller::quantity
