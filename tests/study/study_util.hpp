#pragma once
// Helpers of the study tests: a small study text around the repository's jerk-limited scenario.
#include <gtest/gtest.h>

#include <string>

#include "feeddrive/study/spec.hpp"

namespace feeddrive::study::test {

inline std::string scenarios() { return std::string(FEEDDRIVE_SOURCE_DIR) + "/scenarios/paper"; }

/// A study on the boundary-layer SMC's jerk-limited scenario (shortened), with `rest` appended.
inline std::string study_text(const std::string& rest) {
  return "name: t\nbase: " + scenarios() + "/smc_bl_jerk_limited.yaml\nset: {duration: 0.02}\n" + rest;
}

/// The one-line StudyError of parsing `yaml` (an added test failure if it parses).
inline std::string study_error(const std::string& yaml) {
  try {
    parse_study(yaml, ".", "s.yaml");
  } catch (const StudyError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "error must be one line: " << msg;
    return msg;
  }
  ADD_FAILURE() << "expected a StudyError for:\n" << yaml;
  return "";
}

}  // namespace feeddrive::study::test
