// feeddrive-sim end to end: outputs, exit codes, no half-written output folder, --out checked
// before the run and never replacing a folder feeddrive did not write, names never run as code.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "../support/scratch.hpp"

namespace {
namespace fs = std::filesystem;
using feeddrive::test_support::names;
using feeddrive::test_support::slurp;

const std::string kSim = std::string(FEEDDRIVE_BINARY_DIR) + "/bin/feeddrive-sim";

fs::path scratch() {
  static const fs::path dir = feeddrive::test_support::make_scratch("cli");
  return dir;
}

struct ProcResult {
  int code;
  std::string err;
};

ProcResult run_sim(const std::string& args) {
  const fs::path err = scratch() / "sim_stderr.txt";
  const std::string cmd = kSim + " " + args + " --quiet 2> " + err.string();
  const int status = std::system(cmd.c_str());
  std::ifstream in(err);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
}

// Runs a shell command line in folder `cwd`, capturing stderr.
ProcResult run(const std::string& command, const fs::path& cwd) {
  const fs::path err = scratch() / "run_stderr.txt";
  const std::string cmd = "cd " + cwd.string() + " && " + command + " 2> " + err.string();
  const int status = std::system(cmd.c_str());
  std::ifstream in(err);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
}

fs::path write_file(const std::string& name, const std::string& text) {
  return feeddrive::test_support::write_text(scratch() / name, text);
}

const char* kGood = R"(
name: cli-check
duration: 0.05
control_period: 1e-4
plant: {friction: {model: lugre}, ripple: paper, grinding: {enabled: true}}
controller: {type: sliding_mode, switching: sat, boundary_layer: 1e-3}
reference: {type: scurve, distance: 0.001, max_velocity: 0.02, max_acceleration: 1, max_jerk: 50}
)";

TEST(Cli, WritesTimeseriesSummaryAndPlots) {
  const fs::path scen = write_file("good.yaml", kGood);
  const fs::path out = scratch() / "cli_out";
  fs::remove_all(out);
  const ProcResult r = run_sim(scen.string() + " --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* f :
       {"timeseries.csv", "summary.json", "position.png", "velocity_error.png", "control.png", "forces.png"})
    EXPECT_TRUE(fs::exists(out / f)) << f;

  std::ifstream csv(out / "timeseries.csv");
  std::string header;
  std::getline(csv, header);
  for (const char* col :
       {"t", "xd", "vd", "ad", "x", "x_measured", "v", "z", "u", "f_friction", "f_ripple", "f_grinding"})
    EXPECT_NE(("," + header + ",").find(std::string(",") + col + ","), std::string::npos) << col;
  int rows = 0;
  for (std::string line; std::getline(csv, line);) ++rows;
  EXPECT_EQ(rows, 500);  // 0.05 s / 1e-4 s

  std::ifstream js(out / "summary.json");
  const auto j = nlohmann::json::parse(js);
  EXPECT_EQ(j["steps"].get<long>(), 500);
  EXPECT_NEAR(j["sim_time_s"].get<double>(), 0.05, 1e-12);
  for (const char* key :
       {"wall_time_s", "position_error_max_abs_m", "position_error_rms_m", "velocity_error_max_abs_mps", "control_min",
        "control_max", "control_total_variation", "position_error_max_abs_settled_m"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_LE(j["control_min"].get<double>(), j["control_max"].get<double>());
}

void expect_bad_input(const std::string& scenario_text, const std::string& expected) {
  const fs::path scen = write_file("bad.yaml", scenario_text);
  const fs::path out = scratch() / "cli_bad_out";
  fs::remove_all(out);
  const ProcResult r = run_sim(scen.string() + " --out " + out.string());
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
  EXPECT_FALSE(fs::exists(out)) << "no output folder on bad input";
  for (const auto& e : fs::directory_iterator(scratch()))
    EXPECT_EQ(e.path().filename().string().find(".cli_bad_out.partial"), std::string::npos);
}

TEST(Cli, BadInputExitsTwoWithOneLine) {
  std::string s = kGood;
  expect_bad_input(std::string(kGood) + "plnt: {}\n", "plnt: unknown key (did you mean 'plant'?)");
  expect_bad_input(std::string(kGood).replace(s.find("plant: {"), 8, "plant: {mass: -1, "),
                   "plant.mass = -1: must be > 0");
  expect_bad_input(std::string(kGood).replace(s.find("control_period: 1e-4"), 20, "control_period: 0"),
                   "control_period = 0: must be > 0");
  expect_bad_input(std::string(kGood).replace(s.find("plant: {"), 8, "plant: {mass: .nan, "), "plant.mass = '.nan'");
  expect_bad_input(std::string(kGood).replace(s.find("plant: {"), 8, "plant: {mass: , "), "plant.mass: missing value");
}

// Issue 23: --set KEY=VALUE goes through the same reader as the file's keys.
TEST(Cli, SetIsCheckedLikeTheFile) {
  const fs::path scen = write_file("set.yaml", kGood);
  const fs::path out = scratch() / "cli_set_out";
  fs::remove_all(out);
  for (const auto& [set, expected] : std::vector<std::pair<std::string, std::string>>{
           {"plant.mas=110", "with --set: plant.mas: unknown key (did you mean 'mass'?)"},
           {"plant.mass=-1", "with --set: plant.mass = -1: must be > 0"},
           {"controller.switching=sign", "controller.switching = 'sign': expected one of sgn, sat, tanh"},
           {"plant.mass", "--set plant.mass: expected key=value"},
           {"plant.friction.model.x=1",
            "plant.friction.model.x: plant.friction.model is a single value in the scenario"}}) {
    const ProcResult r = run_sim(scen.string() + " --set " + set + " --out " + out.string());
    EXPECT_EQ(r.code, 2) << set << ": " << r.err;
    EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
  // A value that loads but is implausible for a linear drive: a warning naming the likely unit,
  // and summary.json lists it; a move cut off by `duration` too (issue 23, unit sanity).
  const ProcResult r =
      run_sim(scen.string() + " --set reference.max_velocity=500 --set reference.distance=200 --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("reference.max_velocity: 500 m/s is above any linear drive (10 m/s); mm/s?"), std::string::npos)
      << r.err;
  std::ifstream js(out / "summary.json");
  const auto j = nlohmann::json::parse(js);
  EXPECT_FALSE(j["move_finished"].get<bool>());
  const std::string warnings = j["warnings"].dump();
  EXPECT_NE(warnings.find("reference.distance: 200 m is above the travel of any linear feed drive (5 m); mm?"),
            std::string::npos)
      << warnings;
  EXPECT_NE(warnings.find("the run cuts it off"), std::string::npos) << warnings;
}

TEST(Cli, UnreadableScenarioAndMissingArguments) {
  const ProcResult r = run_sim("/nonexistent.yaml --out " + (scratch() / "x").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/nonexistent.yaml: cannot read the scenario file"), std::string::npos) << r.err;
  EXPECT_EQ(run_sim("").code, 2);
}

TEST(Cli, ScenarioFileSizeIsBoundedAsItIsRead) {
  // The issue's 50 MB name took 4.8 GB and /dev/zero as the scenario was read until the memory
  // ran out (24 GB, killed): a scenario file is at most 1 MiB, refused as it is read.
  expect_bad_input(std::string(kGood) + "# " + std::string((1 << 20) + 10, 'a') + "\n",
                   "bad.yaml: the scenario file is larger than 1048576 bytes");
  const ProcResult r = run_sim("/dev/zero --out " + (scratch() / "zero").string());
  EXPECT_EQ(r.code, 2) << r.err;
  // A device is refused before it is read (issue 19: nothing blocks or fills the memory).
  EXPECT_EQ(r.err, "error: /dev/zero: the scenario file is a device, not a regular file\n");
  EXPECT_FALSE(fs::exists(scratch() / "zero"));
}

// Quoted for the shell of std::system: any text is one word.
std::string sh(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

void expect_one_line_about_out(const ProcResult& r, const std::string& value) {
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
  EXPECT_EQ(r.err.rfind("error: --out " + value, 0), 0u) << r.err;
}

TEST(Cli, EarlierOutputIsReplacedWholeAlsoWithATrailingSlash) {
  const fs::path scen = write_file("good2.yaml", kGood);
  const fs::path base = scratch() / "replace_base";
  fs::remove_all(base);
  fs::create_directories(base);
  const fs::path out = base / "prev";
  ASSERT_EQ(run_sim(scen.string() + " --out " + out.string()).code, 0);  // with plots
  EXPECT_TRUE(fs::exists(out / ".feeddrive-output"));
  EXPECT_TRUE(fs::exists(out / "position.png"));
  std::ofstream(base / "neighbour.txt") << "mine";
  // A file of the user's put into the earlier output: refused before the run, nothing deleted
  // (the issue: "a user's own file inside it is lost too").
  std::ofstream(out / "notes.txt") << "mine";
  const ProcResult refused = run_sim(scen.string() + " --out " + out.string() + "/ --no-plots");
  expect_one_line_about_out(refused, out.string() + "/");
  EXPECT_NE(refused.err.find("holds 'notes.txt', which feeddrive did not write"), std::string::npos) << refused.err;
  EXPECT_EQ(slurp(out / "notes.txt"), "mine");
  EXPECT_TRUE(fs::exists(out / "position.png"));
  fs::remove(out / "notes.txt");
  // "prev/" is "prev": replaced in place and whole (the old bug wrote the temporary folder inside
  // it and then deleted both): the earlier run's plots go with it.
  const ProcResult r = run_sim(scen.string() + " --out " + out.string() + "/ --no-plots");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(out / "position.png"));
  EXPECT_TRUE(fs::exists(out / "timeseries.csv"));
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  EXPECT_EQ(names(base), (std::vector<std::string>{"neighbour.txt", "prev"})) << "no temporary folder left";
  EXPECT_EQ(slurp(base / "neighbour.txt"), "mine");
}

TEST(Cli, RefusesToReplaceAnUnrelatedFolder) {
  const fs::path scen = write_file("good3.yaml", kGood);
  const fs::path out = scratch() / "cli_precious";
  fs::create_directories(out);
  std::ofstream(out / "thesis.tex") << "keep me";
  const ProcResult r = run_sim(scen.string() + " --out " + out.string());
  expect_one_line_about_out(r, out.string());
  EXPECT_NE(r.err.find("not a feeddrive output"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(out / "thesis.tex"));
}

TEST(Cli, AFakeSummaryDoesNotMakeAFolderAnOutput) {
  const fs::path scen = write_file("good4.yaml", kGood);
  const fs::path base = scratch() / "fake_base";
  fs::remove_all(base);
  const fs::path out = base / "results";
  fs::create_directories(out);
  std::ofstream(out / "thesis.tex") << "keep me";
  std::ofstream(out / "summary.json") << "this is not JSON";
  for (const std::string& value : {out.string(), out.string() + "/", out.string() + "//"}) {
    const ProcResult r = run_sim(scen.string() + " --out " + value);
    expect_one_line_about_out(r, value);
    EXPECT_NE(r.err.find("not a feeddrive output"), std::string::npos) << r.err;
  }
  EXPECT_EQ(names(out), (std::vector<std::string>{"summary.json", "thesis.tex"}));
  EXPECT_EQ(slurp(out / "thesis.tex"), "keep me");
  EXPECT_EQ(slurp(out / "summary.json"), "this is not JSON");
  EXPECT_EQ(names(base), std::vector<std::string>{"results"}) << "nothing created next to it";
}

// Every --out that cannot be written is refused with exit 2 and one line before the run: the
// scenario here would run for hours.
TEST(Cli, UnwritableOutRefusedBeforeAnyWork) {
  std::string s = kGood;
  s.replace(s.find("duration: 0.05"), 14, "duration: 1e4");
  const fs::path scen = write_file("endless.yaml", s);
  const fs::path base = scratch() / "unwritable";
  fs::remove_all(base);
  fs::create_directories(base);
  std::ofstream(base / "file") << "a file";
  const std::string long_name(300, 'n');
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "empty path"},
      {"/", "names no folder"},
      {".", "names no folder"},
      {"..", "names no folder"},
      {(base / "file").string(), "not a folder"},
      {(base / "file" / "out").string(), "is not a folder"},
      {(base / "file" / "a" / "b/").string(), "is not a folder"},
      {(base / long_name).string(), "too long"},
  };
  for (const auto& [value, why] : cases) {
    const auto t0 = std::chrono::steady_clock::now();
    const ProcResult r = run_sim(scen.string() + " --out " + sh(value));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    expect_one_line_about_out(r, value.empty() ? "\"\"" : value.substr(0, 40));
    EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
    EXPECT_LT(seconds, 30.0) << "refused before the run";
  }
  EXPECT_EQ(names(base), std::vector<std::string>{"file"});
  EXPECT_EQ(slurp(base / "file"), "a file");
  if (::geteuid() != 0) {  // root writes into read-only folders: permission bits cannot test it
    fs::create_directories(base / "ro");
    fs::permissions(base / "ro", fs::perms::owner_read | fs::perms::owner_exec);
    const ProcResult r = run_sim(scen.string() + " --out " + (base / "ro" / "out").string());
    fs::permissions(base / "ro", fs::perms::owner_all);
    expect_one_line_about_out(r, (base / "ro" / "out").string());
    EXPECT_NE(r.err.find("cannot write in"), std::string::npos) << r.err;
  }
}

// A scenario name, a scenario file name or an --out value is never gnuplot or shell code: the
// run succeeds, the title shows the sanitised name, and nothing else runs.
TEST(Cli, NamesAreNeverRunAsCommands) {
  const fs::path base = scratch() / "inject";
  fs::remove_all(base);
  fs::create_directories(base);
  const fs::path mark = base / "MARK";
  std::string named = kGood;
  named.replace(named.find("name: cli-check"), 15,
                "name: \"x'; system 'touch " + mark.string() + "'; print '`touch " + mark.string() + "`@x\"");
  const fs::path scen1 = base / "named.yaml";
  std::ofstream(scen1) << named;
  std::string unnamed = kGood;
  unnamed.erase(unnamed.find("name: cli-check"), 15);
  const fs::path scen2 = base / "a'; system 'touch MARK'; print '.yaml";  // the name is the file's stem
  std::ofstream(scen2) << unnamed;
  const fs::path scen3 = base / "`touch MARK`.yaml";
  std::ofstream(scen3) << unnamed;
  int k = 0;
  for (const fs::path& scen : {scen1, scen2, scen3}) {
    const fs::path out = base / ("o'; touch MARK; echo '" + std::to_string(k++));
    const ProcResult r = run(kSim + " " + sh(scen.string()) + " --out " + sh(out.string()) + " --quiet", base);
    ASSERT_EQ(r.code, 0) << scen << ": " << r.err;
    for (const char* f : {"position.png", "velocity_error.png", "control.png", "forces.png"})
      EXPECT_TRUE(fs::exists(out / f)) << f;
    EXPECT_FALSE(fs::exists(mark)) << scen;
    EXPECT_FALSE(fs::exists(out / "MARK")) << scen;
  }
  EXPECT_NE(slurp(base / "o'; touch MARK; echo '1" / "plots.gp").find("title \"a?; system ?touch MARK?; print ?\""),
            std::string::npos);
}

}  // namespace

// --- Long runs (issue 11): recording options, impossible runs, Ctrl-C, stale staging folders ---

std::vector<std::string> csv_lines(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> out;
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

TEST(Cli, OutputEveryAndColumnsKeepTheSummaryOfEveryStep) {
  const fs::path all_out = scratch() / "cli_all", some_out = scratch() / "cli_some";
  fs::remove_all(all_out);
  fs::remove_all(some_out);
  ASSERT_EQ(run_sim(write_file("all.yaml", kGood).string() + " --out " + all_out.string() + " --no-plots").code, 0);
  const ProcResult r =
      run_sim(write_file("some.yaml", std::string(kGood) + "output: {every: 7, columns: [t, x, u]}\n").string() +
              " --out " + some_out.string() + " --no-plots");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto all = csv_lines(all_out / "timeseries.csv"), some = csv_lines(some_out / "timeseries.csv");
  ASSERT_EQ(some.front(), "t,x,u");
  ASSERT_EQ(some.size(), 1u + (500 + 6) / 7);  // rows k = 0, 7, ..., 497
  // each kept row is the full row's t, x and u, byte for byte
  const auto field = [](const std::string& line, int c) {
    std::stringstream ss(line);
    std::string f;
    for (int i = 0; i <= c; ++i) std::getline(ss, f, ',');
    return f;
  };
  for (std::size_t i = 1; i < some.size(); ++i) {
    const std::string& full = all[1 + 7 * (i - 1)];
    EXPECT_EQ(some[i], field(full, 0) + "," + field(full, 5) + "," + field(full, 12)) << i;
  }
  // the summary still covers every step: identical to the run that kept every row
  std::ifstream a(all_out / "summary.json"), b(some_out / "summary.json");
  auto ja = nlohmann::json::parse(a), jb = nlohmann::json::parse(b);
  for (auto* j : {&ja, &jb})
    for (const char* k : {"wall_time_s", "realtime_factor", "scenario", "scenario_path"}) j->erase(k);
  EXPECT_EQ(ja, jb);
}

TEST(Cli, BadOutputOptionsAndImpossibleRunsExitTwoBeforeAnyWork) {
  expect_bad_input(std::string(kGood) + "output: {columns: [t, speed]}\n", "output.columns: unknown column 'speed'");
  expect_bad_input(std::string(kGood) + "output: {every: 0}\n", "output.every = 0: must be >= 1");
  expect_bad_input(std::string(kGood) + "output: {evry: 2}\n", "output.evry: unknown key (did you mean 'every'?)");
  std::string s = kGood;
  // 1e16 steps: was std::bad_alloc with exit 1
  expect_bad_input(std::string(kGood).replace(s.find("duration: 0.05"), 14, "duration: 1e12"),
                   "duration = 1e12, control_period = 1e-4: 1e+16 steps; a run has at most 1e+10 steps");
  // was "shorter than one control period" (the step count overflowed)
  expect_bad_input(std::string(kGood).replace(s.find("duration: 0.05"), 14, "duration: 1e300"),
                   "duration = 1e300, control_period = 1e-4: 1e+304 steps; a run has at most 1e+10 steps");
}

TEST(Cli, TimeseriesThatCannotFitTheDiskIsRefusedBeforeAnyWork) {
  // 1e10 steps (within the step limit) need at least 400 GB of CSV: more than a test machine has.
  std::string s = kGood;
  std::string text = std::string(kGood).replace(s.find("duration: 0.05"), 14, "duration: 1e6");
  const fs::path out = scratch() / "cli_huge";
  const ProcResult r = run_sim(write_file("huge.yaml", text).string() + " --out " + out.string());
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("duration, control_period, output.every, output.columns: timeseries.csv needs at least 400 GB"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

bool has_staging(const std::string& name) {
  for (const auto& e : fs::directory_iterator(scratch()))
    if (e.path().filename().string().rfind("." + name + ".partial-", 0) == 0) return true;
  return false;
}

TEST(Cli, ACsvThatCannotFitIsRefusedOnItsFirstRowsWithExitTwo) {
  // The bound before the run takes 2 bytes a value; real rows take about 12. A run sized to
  // pass that bound (free / 100 bytes' worth of rows: 40 % of the disk at 2 bytes x 20 values)
  // but needing ~2.5x the free space once written is refused after its first 1,000 rows.
  struct statvfs st {};
  ASSERT_EQ(::statvfs(scratch().c_str(), &st), 0);
  const double free_bytes = static_cast<double>(st.f_bavail) * static_cast<double>(st.f_frsize);
  const double steps = std::min(1e10, std::floor(free_bytes / 100.0));
  if (steps * 20 * 2 > 0.9 * free_bytes) GTEST_SKIP() << "disk too small for this check";
  // Rows of this scenario take ~250 bytes: skip where even that would fit (a disk over 2 TB free,
  // where the 1e10-step limit comes first), rather than start a run that long.
  if (steps * 200 < 1.2 * free_bytes) GTEST_SKIP() << "disk too large for this check";
  std::string s = kGood;
  const std::string text =
      std::string(kGood).replace(s.find("duration: 0.05"), 14, "duration: " + std::to_string(steps * 1e-4));
  const fs::path out = scratch() / "cli_projected";
  const ProcResult r = run_sim(write_file("projected.yaml", text).string() + " --out " + out.string() + " --no-plots");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("duration, control_period, output.every, output.columns: timeseries.csv would take about"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("measured on the first 1000"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(has_staging("cli_projected"));
}

TEST(Cli, InterruptLeavesNoOutputAndNoStagingFolder) {
  std::string s = kGood;
  const fs::path scen =
      write_file("long.yaml", std::string(kGood).replace(s.find("duration: 0.05"), 14, "duration: 1000"));
  for (int sig : {SIGINT, SIGTERM}) {
    const fs::path out = scratch() / "cli_interrupted";
    fs::remove_all(out);
    const pid_t pid = ::fork();
    if (pid == 0) {
      ::execl(kSim.c_str(), kSim.c_str(), scen.c_str(), "--out", out.c_str(), "-q", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    // wait until the run has started writing (its staging folder exists), then interrupt it
    for (int i = 0; i < 200 && !has_staging("cli_interrupted"); ++i) ::usleep(20000);
    ASSERT_TRUE(has_staging("cli_interrupted"));
    ::usleep(300000);  // under test: the signal 0.3 s into the run (deliberate, not a wait)
    ::kill(pid, sig);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 128 + sig);
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(has_staging("cli_interrupted")) << "the staged folder is removed on " << sig;
  }
}

TEST(Cli, AStagingFolderLeftByAKilledRunIsRemovedByTheNextRun) {
  const fs::path out = scratch() / "cli_stale";
  fs::remove_all(out);
  // a staging folder of a feeddrive process that no longer runs (kill -9): marked, PID dead
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  const fs::path stale = scratch() / (".cli_stale.partial-" + std::to_string(dead) + "-0");
  fs::create_directories(stale);
  std::ofstream(stale / ".feeddrive-output") << "feeddrive-output\nformat: 1\ntool: feeddrive-sim\n";
  std::ofstream(stale / "timeseries.csv") << "t\n0\n";
  // one that is not marked is not ours: left alone
  const fs::path foreign = scratch() / (".cli_stale.partial-" + std::to_string(dead) + "-1");
  fs::create_directories(foreign);
  std::ofstream(foreign / "notes.txt") << "mine";
  ASSERT_EQ(run_sim(write_file("stale.yaml", kGood).string() + " --out " + out.string() + " --no-plots").code, 0);
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(foreign / "notes.txt"));
  fs::remove_all(foreign);
}

namespace {

TEST(Cli, FrequencyResponseWritesTableDataAndBodePlots) {
  // feeddrive-sim --frequency-response (docs/analysis.md): two frequencies of the linear drive;
  // the numbers are tested in tests/analysis, here the tool: files, the stated amplitude, exit codes.
  const fs::path scn = write_file("fr.yaml",
                                  "name: fr\nduration: 1.0\ncontrol_period: 1.0e-4\nplant: {friction: {model: none}}\n"
                                  "controller: {type: cascade, tuning: rule}\n");
  const fs::path out = scratch() / "fr_out";
  const ProcResult ok =
      run_sim(scn.string() + " --out " + out.string() + " --frequency-response --fr-frequencies 50,500 --fr-force 20");
  ASSERT_EQ(ok.code, 0) << ok.err;
  for (const char* f : {"frequency_response.csv", "frequency_response.json", "bode_reference.png",
                        "bode_compliance.png", "bode_loop.png"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  const auto j = nlohmann::json::parse(slurp(out / "frequency_response.json"));
  EXPECT_EQ(j["excitation"]["force_amplitude_N"], 20.0);
  EXPECT_EQ(j["excitation"]["reference_amplitude_m"], 1e-5);
  EXPECT_TRUE(j["min_dynamic_stiffness_N_per_um"].is_number());
  // one line naming the option and the value, exit 2, nothing written
  const fs::path bad = scratch() / "fr_bad";
  const ProcResult e = run_sim(scn.string() + " --out " + bad.string() + " --frequency-response --fr-frequencies 7000");
  EXPECT_EQ(e.code, 2);
  EXPECT_EQ(e.err, "error: --fr-frequencies 7000: must be > 0 and below Nyquist 5000 Hz\n");
  EXPECT_FALSE(fs::exists(bad));
  // review F10: an open-loop controller has no loop to measure: one line, exit 2
  const fs::path ol =
      write_file("fr_ol.yaml",
                 "name: fr_ol\nduration: 1.0\ncontrol_period: 1.0e-4\nplant: {friction: {model: none}}\n"
                 "controller: {type: open_loop, kind: step, amplitude: 12.0}\nreference: {type: none}\n");
  const ProcResult eo = run_sim(ol.string() + " --out " + bad.string() + " --frequency-response --fr-frequencies 50");
  EXPECT_EQ(eo.code, 2);
  EXPECT_EQ(eo.err.rfind("error: controller.type open_loop: no feedback loop to measure", 0), 0u) << eo.err;
  EXPECT_EQ(std::count(eo.err.begin(), eo.err.end(), '\n'), 1) << eo.err;
  // review F9, F8: the scenario's plausibility warnings are logged and written, as after a run;
  // a run not made says "not measured"
  const fs::path heavy = scratch() / "fr_heavy";
  const fs::path h_out = scratch() / "fr_heavy_stdout.txt", h_err = scratch() / "fr_heavy_stderr.txt";
  const std::string cmd = kSim + " " + scn.string() + " --out " + heavy.string() +
                          " --set plant.mass=5e4 --frequency-response --fr-frequencies 50 --fr-force 0 --no-plots > " +
                          h_out.string() + " 2> " + h_err.string();
  ASSERT_EQ(std::system(cmd.c_str()), 0) << slurp(h_err);
  EXPECT_NE(slurp(h_err).find("plant.mass: 50000 kg is above"), std::string::npos) << slurp(h_err);
  EXPECT_NE(slurp(h_out).find("not measured (--fr-force 0)"), std::string::npos) << slurp(h_out);
  const auto jh = nlohmann::json::parse(slurp(heavy / "frequency_response.json"));
  ASSERT_TRUE(jh["warnings"].is_array());
  EXPECT_NE(jh["warnings"][0].get<std::string>().find("plant.mass: 50000 kg is above"), std::string::npos)
      << jh["warnings"];
}

}  // namespace
