#pragma once
// The one-line ScenarioError message of parsing `yaml` (an added test failure if it parses).
#include <gtest/gtest.h>

#include <string>

#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::sim::test {

inline std::string error_of(const std::string& yaml) {
  try {
    parse_scenario(yaml, ".", "s.yaml");
  } catch (const ScenarioError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "error must be one line: " << msg;
    return msg;
  }
  ADD_FAILURE() << "expected a ScenarioError for:\n" << yaml;
  return "";
}

}  // namespace feeddrive::sim::test
