#include "feeddrive/plant/parameter_table.hpp"

namespace feeddrive::plant {

std::vector<fields::FlatValue> parameter_table(const PlantParams& p) {
  std::vector<fields::FlatValue> t = fields::flatten(p, table_excluded_keys());
  const std::vector<std::string>& derived = table_derived_keys();
  t.push_back({derived[0], p.thrust_gain(), "", false});
  t.push_back({derived[1], p.grinding.damping(), "", false});
  return t;
}

}  // namespace feeddrive::plant
