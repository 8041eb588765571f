#pragma once
// Scratch folders and file helpers shared by the test programs that run the executables
// (tests/sim, tests/fit, tests/study). ctest runs every test in its own process and several at
// once, so a scratch folder is named by its tag and the process id; every folder made here is
// removed when the test program ends.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace feeddrive::test_support {

namespace detail {
inline std::vector<std::filesystem::path>& scratch_dirs() {
  static std::vector<std::filesystem::path> dirs;
  return dirs;
}
struct ScratchCleanup : ::testing::Environment {
  void TearDown() override {
    std::error_code ec;
    for (const auto& d : scratch_dirs()) std::filesystem::remove_all(d, ec);
  }
};
inline ::testing::Environment* const kScratchCleanup = ::testing::AddGlobalTestEnvironment(new ScratchCleanup);
}  // namespace detail

/// A new, empty folder TempDir()/feeddrive-TAG-PID, removed when the test program ends. Call it
/// once per tag (keep the result in a function-local static).
inline std::filesystem::path make_scratch(const std::string& tag) {
  const std::filesystem::path d =
      std::filesystem::path(::testing::TempDir()) / ("feeddrive-" + tag + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  detail::scratch_dirs().push_back(d);
  return d;
}

/// The whole file, as bytes ("" if it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The names in folder `dir`, sorted.
inline std::vector<std::string> names(const std::filesystem::path& dir) {
  std::vector<std::string> v;
  for (const auto& e : std::filesystem::directory_iterator(dir)) v.push_back(e.path().filename().string());
  std::sort(v.begin(), v.end());
  return v;
}

/// Writes `text` to `p` as bytes and returns `p`.
inline std::filesystem::path write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

}  // namespace feeddrive::test_support
