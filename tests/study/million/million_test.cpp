// Issue 19, point 9: a study of 10^6 cases (the documented maximum) starts running cases at once,
// stays small in memory and stops on Ctrl-C. Before the fix it expanded and resolved every case
// before running any: after 10 minutes it held 1.4 GB, had written nothing, and ignored SIGINT and
// SIGTERM. Now cases are made and resolved one at a time as they are handed out (case_at), and
// results.csv is written in study order through a bounded window.
//
// Not a timing test: the bounds below are 6x (first case) and 5x (exit after SIGINT) what the
// goals of the issue ask (10 s, 1 s), for a machine shared with other builds; the measured
// figures are in docs/study.md ("A study of 10^6 cases"). It holds the "heavy" lock.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "../../support/scratch.hpp"

namespace {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

const std::string kStudy = std::string(FEEDDRIVE_BINARY_DIR) + "/bin/feeddrive-study";

// 1000 x 1000 grid points of the jerk-limited SMC scenario, each a 10-step run (1 ms at 10 kHz).
fs::path write_study(const fs::path& dir) {
  std::ostringstream axis;
  for (int i = 0; i < 1000; ++i) axis << (i ? ", " : "") << 0.8 + 0.4 * i / 999.0;
  const fs::path p = dir / "million.yaml";
  std::ofstream(p) << "name: million\nbase: " FEEDDRIVE_SOURCE_DIR "/scenarios/paper/smc_bl_jerk_limited.yaml\n"
                   << "set: {duration: 0.001}\nfamilies:\n  - name: grid\n    grid:\n"
                   << "      - {key: plant.mass, scale: [" << axis.str() << "]}\n"
                   << "      - {key: plant.friction.coulomb_force, scale: [" << axis.str() << "]}\n";
  return p;
}

// Starts feeddrive-study STUDY --out OUT (no shell), its stderr into `err`.
pid_t start_study(const fs::path& study, const fs::path& out, const fs::path& err) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 2);
    ::execl(kStudy.c_str(), kStudy.c_str(), study.c_str(), "--out", out.c_str(), "--no-plots", "-q", nullptr);
    ::_exit(127);
  }
  return pid;
}

std::size_t count_finished(const fs::path& cases) {
  std::size_t n = 0;
  std::error_code ec;
  for (fs::directory_iterator it(cases, ec), end; !ec && it != end; it.increment(ec))
    n += it->path().extension() == ".json";
  return n;
}

TEST(StudyMillion, StartsAtOnceStaysSmallAndStopsOnCtrlC) {
  const fs::path dir = feeddrive::test_support::make_scratch("million");
  const fs::path study = write_study(dir), out = dir / "out", err = dir / "stderr.txt";

  const auto start = Clock::now();
  const pid_t pid = start_study(study, out, err);
  ASSERT_GT(pid, 0);
  // The first case done: measured 2.6 s on the shared 2-core machine (docs/study.md); the goal is
  // 10 s; 60 s here so a loaded machine does not fail it.
  while (count_finished(out / "cases") == 0 && Clock::now() - start < std::chrono::seconds(60))
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const double first_s = std::chrono::duration<double>(Clock::now() - start).count();
  const bool started = count_finished(out / "cases") > 0;
  EXPECT_TRUE(started) << "no case finished within 60 s of the start";
  // Running until 600 cases are done (about 5 s at the measured 130 cases/s; deadline 60 s from
  // the start): more than the window of 256 cases handed out, so the peak below is the running
  // study's, not its start's.
  while (count_finished(out / "cases") < 600 && Clock::now() - start < std::chrono::seconds(60))
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const std::size_t finished = count_finished(out / "cases");

  ASSERT_EQ(::kill(pid, SIGINT), 0);
  const auto sent = Clock::now();
  int status = 0;
  struct rusage ru {};
  pid_t done = 0;
  while ((done = ::wait4(pid, &status, WNOHANG, &ru)) == 0 && Clock::now() - sent < std::chrono::seconds(20))
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const double stop_s = std::chrono::duration<double>(Clock::now() - sent).count();
  if (done == 0) {  // never leave it running
    ::kill(pid, SIGKILL);
    ::wait4(pid, &status, 0, &ru);
    FAIL() << "still running 20 s after SIGINT";
  }
  std::ifstream in(err);
  std::stringstream ss;
  ss << in.rdbuf();
  std::printf("first case done after %.2f s; %zu cases finished; exit %.3f s after SIGINT; peak RSS %.1f MB\n", first_s,
              finished, stop_s, ru.ru_maxrss / 1024.0);
  ASSERT_TRUE(WIFEXITED(status)) << ss.str();
  EXPECT_EQ(WEXITSTATUS(status), 130) << ss.str();
  EXPECT_NE(ss.str().find("interrupted by SIGINT"), std::string::npos) << ss.str();
  // Goal 1 s (the running cases poll for Ctrl-C, the loop waits at most 200 ms); 5 s for a
  // loaded machine.
  EXPECT_LT(stop_s, 5.0);
  // Holding every case (resolved scenario and outcome, ~1.4 kB each) would be 1.4 GB: the cases
  // in flight, the window of 256 and ~30 bytes per finished case for report.md are a few MB over
  // the process's own 15 MB.
  EXPECT_LT(ru.ru_maxrss, 200L * 1024) << "peak RSS " << ru.ru_maxrss << " kB";
  EXPECT_GE(finished, 600u) << "fewer than 600 cases finished within 60 s of the start";
  // Nothing of results.csv while unfinished: it appears whole at the end.
  EXPECT_FALSE(fs::exists(out / "results.csv"));
  EXPECT_FALSE(fs::exists(out / "results.csv.partial"));
}

// SIGTERM half a second after the start: the study is still checking its probe cases (about a
// second of resolving) or has just started running; either way it stops at once with 128 + 15.
TEST(StudyMillion, SigtermDuringSetUpStopsAtOnce) {
  const fs::path dir = feeddrive::test_support::make_scratch("million-term");
  const fs::path study = write_study(dir), out = dir / "out";
  const pid_t pid = start_study(study, out, dir / "stderr.txt");
  ASSERT_GT(pid, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // under test: 0.5 s in (a point in time)
  ASSERT_EQ(::kill(pid, SIGTERM), 0);
  const auto sent = Clock::now();
  int status = 0;
  pid_t done = 0;
  while ((done = ::waitpid(pid, &status, WNOHANG)) == 0 && Clock::now() - sent < std::chrono::seconds(20))
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const double stop_s = std::chrono::duration<double>(Clock::now() - sent).count();
  if (done == 0) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
    FAIL() << "still running 20 s after SIGTERM";
  }
  std::printf("exit %.3f s after SIGTERM\n", stop_s);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 143);
  EXPECT_LT(stop_s, 5.0);  // goal 1 s; generous for a loaded machine (see the top)
}

}  // namespace
