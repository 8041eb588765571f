// Peak memory of a long run does not grow with the number of steps (issue "Long runs"):
// feeddrive-sim runs the same scenario for 1e5 and 1e6 steps, each in a child process, and the
// child's peak resident set (wait4's ru_maxrss) is compared. Keeping every record, as before the
// streaming writer, costs about 170 bytes per step: +150 MB between the two runs. Not a timing.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

namespace {
namespace fs = std::filesystem;

const std::string kSim = std::string(FEEDDRIVE_BINARY_DIR) + "/bin/feeddrive-sim";

struct Child {
  int code{-1};
  long maxrss_kb{0};
};

// Runs feeddrive-sim with `args` (no shell), waits with wait4 for its own resource usage.
Child run_sim(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  std::string prog = kSim;
  argv.push_back(prog.data());
  std::vector<std::string> a = args;
  for (auto& s : a) argv.push_back(s.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::execv(kSim.c_str(), argv.data());
    ::_exit(127);
  }
  int status = 0;
  struct rusage ru {};
  ::wait4(pid, &status, 0, &ru);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ru.ru_maxrss};
}

fs::path scenario(const fs::path& dir, double duration) {
  std::ifstream in(FEEDDRIVE_SOURCE_DIR "/scenarios/paper/beyond_jerk_limited.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const auto at = text.find("duration: 1.5");
  text.replace(at, 13, "duration: " + std::to_string(duration));
  // every 10th row: the CSV stays small (the writer's memory does not depend on it either);
  // the summary and the plot reduction still see every step.
  text += "output: {every: 10}\n";
  const fs::path p = dir / ("long_" + std::to_string(static_cast<long>(duration)) + ".yaml");
  std::ofstream(p) << text;
  return p;
}

long lines(const fs::path& p) {
  std::ifstream in(p);
  long n = 0;
  std::string l;
  while (std::getline(in, l)) ++n;
  return n;
}

}  // namespace

TEST(LongRun, PeakMemoryDoesNotGrowWithTheSteps) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("feeddrive-memory-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  // 1e5 and 1e6 steps of 0.1 ms
  const Child small = run_sim({scenario(dir, 10).string(), "--out", (dir / "small").string(), "--no-plots", "-q"});
  const Child large = run_sim({scenario(dir, 100).string(), "--out", (dir / "large").string(), "--no-plots", "-q"});
  ASSERT_EQ(small.code, 0);
  ASSERT_EQ(large.code, 0);
  std::ifstream js(dir / "large" / "summary.json");
  const auto j = nlohmann::json::parse(js);
  EXPECT_EQ(j["steps"].get<long>(), 1000000);
  EXPECT_EQ(lines(dir / "large" / "timeseries.csv"), 100001);  // header + every 10th of 1e6 steps
  std::printf("peak RSS: %ld kB at 1e5 steps, %ld kB at 1e6 steps\n", small.maxrss_kb, large.maxrss_kb);
  // Bounds: the growth allowed is 8 MB for 900,000 more steps (< 9 bytes per step, against 170
  // when every record was kept); the whole process (CVODE, the 1 MiB CSV buffer, the histogram
  // and the plot buckets, the C++ runtime) stays under 64 MB (measured about 20 MB).
  EXPECT_LT(large.maxrss_kb - small.maxrss_kb, 8 * 1024);
  EXPECT_LT(large.maxrss_kb, 64 * 1024);
  // getrusage(RUSAGE_CHILDREN) agrees: the largest peak of the waited-for children is the
  // larger run's (wait4 reports each child's own; both come from the kernel's ru_maxrss).
  struct rusage children {};
  ASSERT_EQ(::getrusage(RUSAGE_CHILDREN, &children), 0);
  EXPECT_EQ(children.ru_maxrss, std::max(small.maxrss_kb, large.maxrss_kb));
  fs::remove_all(dir);
}
