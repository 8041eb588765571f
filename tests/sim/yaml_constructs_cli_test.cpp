// Issue 19, point 8: every tool that reads YAML (feeddrive-sim, -launch, -fit, -study) refuses a
// recursive alias and a merge key with exit 2 and one line naming the construct and its place.
// Before the fix, `friction: &f {model: lugre, inner: *f}` crashed all four (exit 139): yaml-cpp
// builds the alias as the anchor's own node, and every traversal of the cycle overflowed the stack.
// All four read YAML through sim::load_yaml_strict (yaml_reader.hpp).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "../support/scratch.hpp"

namespace {
namespace fs = std::filesystem;

fs::path scratch() {
  static const fs::path dir = feeddrive::test_support::make_scratch("yaml-constructs");
  return dir;
}

std::string bin(const std::string& tool) { return std::string(FEEDDRIVE_BINARY_DIR) + "/bin/" + tool; }

struct Result {
  int code;
  std::string err;
};

Result run(const std::string& command) {
  const fs::path err = scratch() / "stderr.txt";
  const int status = std::system(("cd " + scratch().string() + " && " + command + " 2> " + err.string()).c_str());
  std::ifstream in(err);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), ss.str()};
}

// A complete scenario (the paper's jerk-limited SMC, shortened) with one more line.
std::string scenario_with(const std::string& line) {
  std::ifstream in(std::string(FEEDDRIVE_SOURCE_DIR) + "/scenarios/paper/smc_bl_jerk_limited.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str() + line;
}

const std::string kRecursive = "extra: &f {model: lugre, inner: *f}\n";
const std::string kMerge = "defaults: &d {mass: 1}\nextra:\n  <<: *d\n";

void expect_refused(const Result& r, const std::string& what, const std::string& command) {
  EXPECT_EQ(r.code, 2) << command << "\n" << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << command << "\n" << r.err;
  EXPECT_NE(r.err.find(what), std::string::npos) << command << "\n" << r.err;
}

class YamlConstructs : public ::testing::TestWithParam<std::pair<std::string, std::string>> {};

TEST_P(YamlConstructs, EveryToolExitsTwoWithOneLineNamingIt) {
  const auto& [text, what] = GetParam();
  const fs::path s = feeddrive::test_support::write_text(scratch() / "s.yaml", scenario_with(text));
  const fs::path data = feeddrive::test_support::write_text(scratch() / "d.csv", "t,x,u\n0,0,0\n0.001,0,0\n");
  const std::string out = (scratch() / "out").string();
  const std::string commands[] = {
      bin("feeddrive-sim") + " s.yaml --out " + out,
      bin("feeddrive-launch") + " s.yaml --out " + out,
      bin("feeddrive-fit") + " -s s.yaml -d " + data.string() + " --out " + out,
  };
  for (const std::string& c : commands) {
    expect_refused(run(c), "s.yaml: " + what, c);
    EXPECT_FALSE(fs::exists(out)) << c;
  }
  // The study: the scenario as its base file, as an inline base map, and as a controller's file.
  feeddrive::test_support::write_text(scratch() / "file.yaml", "name: t\nbase: s.yaml\n");
  feeddrive::test_support::write_text(
      scratch() / "ctrl.yaml",
      "name: t\nbase: " + std::string(FEEDDRIVE_SOURCE_DIR) +
          "/scenarios/paper/smc_bl_jerk_limited.yaml\ncontrollers: [{name: c, scenario: s.yaml}]\n");
  std::string indented = "name: t\nbase:\n";
  std::istringstream lines(scenario_with(text));
  for (std::string l; std::getline(lines, l);) indented += "  " + l + "\n";
  feeddrive::test_support::write_text(scratch() / "inline.yaml", indented);
  for (const std::string study : {"file.yaml", "ctrl.yaml", "inline.yaml"}) {
    const std::string c = bin("feeddrive-study") + " " + study + " --out " + out;
    expect_refused(run(c), what.substr(what.find(": ") + 2), c);
    EXPECT_FALSE(fs::exists(out)) << c;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Issue19, YamlConstructs,
    ::testing::Values(
        std::make_pair(kRecursive, "line 22, column 33: extra.inner: recursive YAML alias *f inside its own anchor &f"),
        std::make_pair(kMerge, "line 24, column 3: extra.<<: YAML merge key (<<) not supported")));

}  // namespace
