// feeddrive-fit end to end: the real executable on bad inputs (exit 2, exactly one line on stderr
// naming the file, line and column or key) and on one good run (a 15 N constant force hidden in
// 4 s of feeddrive-sim data: found, fitted, written, loadable).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "../support/scratch.hpp"
#include "feeddrive/fit/report.hpp"
#include "feeddrive/plant/effects.hpp"
#include "feeddrive/sim/scenario.hpp"

namespace {
namespace fs = std::filesystem;
using feeddrive::test_support::slurp;

const std::string kFit = std::string(FEEDDRIVE_BINARY_DIR) + "/bin/feeddrive-fit";
const std::string kSim = std::string(FEEDDRIVE_BINARY_DIR) + "/bin/feeddrive-sim";
const fs::path kScenarios = fs::path(FEEDDRIVE_SOURCE_DIR) / "scenarios" / "fit";

fs::path scratch() {
  static const fs::path dir = feeddrive::test_support::make_scratch("fit-cli");
  return dir;
}

fs::path write_file(const std::string& name, const std::string& text) {
  return feeddrive::test_support::write_text(scratch() / name, text);
}

struct ProcResult {
  int code;
  std::string out;
  std::string err;
};

// Runs `exe args` under timeout (nothing may hang the test), capturing stdout and stderr.
ProcResult run(const std::string& exe, const std::string& args, int timeout_s = 600) {
  const fs::path out = scratch() / "stdout.txt", err = scratch() / "stderr.txt";
  const std::string cmd =
      "timeout " + std::to_string(timeout_s) + " " + exe + " " + args + " > " + out.string() + " 2> " + err.string();
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

ProcResult run_fit(const std::string& args) { return run(kFit, args); }

// A valid model (the bad-input cases fail on the data, before any fit).
fs::path model_scenario() { return kScenarios / "model.yaml"; }

// n rows of t, x, u (1 kHz, a slow sine): valid data, for the cases that break one thing in it.
std::vector<std::string> good_rows(int n) {
  std::vector<std::string> rows;
  for (int k = 0; k < n; ++k) {
    const double t = k * 1e-3;
    std::ostringstream r;
    r.precision(10);
    r << t << "," << 0.01 * std::sin(t) << "," << 0.1 * std::cos(t);
    rows.push_back(r.str());
  }
  return rows;
}

std::string csv(const std::string& header, const std::vector<std::string>& rows) {
  std::string s = header + "\n";
  for (const auto& r : rows) s += r + "\n";
  return s;
}

// The data file `data` (written as `name`) must be refused: exit 2, one line on stderr containing
// every string of `expected`, no output folder. Returns the line.
std::string expect_data_error(const std::string& name, const std::string& data,
                              const std::vector<std::string>& expected, const std::string& extra_args = "") {
  SCOPED_TRACE(name);
  const fs::path file = write_file(name, data);
  const fs::path out = scratch() / ("out_" + name);
  const ProcResult r = run_fit("--scenario " + model_scenario().string() + " --data " + file.string() + " --out " +
                               out.string() + " --no-plots -q " + extra_args);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "exactly one line: [" << r.err << "]";
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  for (const auto& e : expected) EXPECT_NE(r.err.find(e), std::string::npos) << "want '" << e << "' in: " << r.err;
  EXPECT_FALSE(fs::exists(out)) << "no output folder on bad input";
  return r.err;
}

TEST(FitCli, MissingPositionColumn) {
  // The file, the missing column; the header it did find helps spot a misnamed column.
  expect_data_error("no_x.csv", csv("t,pos,u", good_rows(100)), {"no_x.csv", "missing column 'x'", "t,pos,u"});
  // --position-column names the column looked for.
  expect_data_error("no_xm.csv", csv("t,x,u", good_rows(100)), {"no_xm.csv", "missing column 'x_measured'"},
                    "--position-column x_measured");
}

TEST(FitCli, MissingInputColumn) {
  expect_data_error("no_u.csv", csv("t,x,volts", good_rows(100)), {"no_u.csv", "'u'", "'force_N'"});
}

TEST(FitCli, NaNNamesLineAndColumn) {
  auto rows = good_rows(100);
  rows[41] = "0.041,nan,0.1";  // file line 43: the header is line 1, rows[0] is line 2
  expect_data_error("nan.csv", csv("t,x,u", rows), {"nan.csv:43:7:", "column 'x'", "'nan'"});
  rows = good_rows(100);
  rows[9] = "0.009,0.0,";  // an empty cell: line 11, column u
  expect_data_error("empty_cell.csv", csv("t,x,u", rows), {"empty_cell.csv:11:11:", "column 'u': missing value"});
}

TEST(FitCli, RepeatedTime) {
  auto rows = good_rows(100);
  rows[20] = "0.019,0.0,0.1";  // same t as rows[19]: line 22
  expect_data_error("repeat.csv", csv("t,x,u", rows),
                    {"repeat.csv:22:1:", "column 't'", "0.019 is not greater than the previous t = 0.019 (line 21)"});
}

TEST(FitCli, TimeGoingBackwards) {
  auto rows = good_rows(100);
  rows[30] = "0.025,0.0,0.1";  // before rows[29] (0.029): line 32
  expect_data_error(
      "backwards.csv", csv("t,x,u", rows),
      {"backwards.csv:32:1:", "column 't'", "0.025 is not greater than the previous t = 0.029 (line 31)"});
}

TEST(FitCli, TooFewSamples) {
  expect_data_error("few.csv", csv("t,x,u", good_rows(10)), {"few.csv", "10 samples", "too few"});
}

TEST(FitCli, UnreadableDataFile) {
  const fs::path out = scratch() / "out_missing";
  const ProcResult r =
      run_fit("--scenario " + model_scenario().string() + " --data " + (scratch() / "does_not_exist.csv").string() +
              " --out " + out.string() + " -q --no-plots");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("does_not_exist.csv: cannot open"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  // The same for a log (by extension: the LCM reader).
  const ProcResult l = run_fit("--scenario " + model_scenario().string() + " --data " +
                               (scratch() / "does_not_exist.lcmlog").string() + " --out " + out.string() + " -q");
  EXPECT_EQ(l.code, 2) << l.err;
  EXPECT_EQ(std::count(l.err.begin(), l.err.end(), '\n'), 1) << l.err;
  EXPECT_NE(l.err.find("does_not_exist.lcmlog: cannot open"), std::string::npos) << l.err;
  // An empty CSV file.
  expect_data_error("empty.csv", "", {"empty.csv", "no header line"});
}

TEST(FitCli, FolderSeparatorAndByteOrderMark) {
  // A folder given as the data file says so.
  fs::create_directories(scratch() / "adir");
  const fs::path out = scratch() / "out_adir";
  const ProcResult r = run_fit("--scenario " + model_scenario().string() + " --data " + (scratch() / "adir").string() +
                               " --out " + out.string() + " -q --no-plots");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("is a folder"), std::string::npos) << r.err;
  // Semicolons instead of commas: the message says what separates columns.
  expect_data_error("semicolons.csv", csv("t;x;u", good_rows(100)), {"missing column 't'", "separated by commas"});
  // A UTF-8 byte-order mark before the header is not part of the first column's name: the file
  // is read, and fails only where it is meant to (too few rows).
  expect_data_error("bom.csv", "\xEF\xBB\xBF" + csv("t,x,u", good_rows(10)), {"bom.csv", "10 samples"});
}

TEST(FitCli, ArgumentErrorsAreOneLineAndComeFirst) {
  // A missing or out-of-range option: one line, exit 2.
  for (const std::string args :
       {"--scenario x.yaml --data y.csv", "--scenario x.yaml --data y.csv --out z --max-effects 99"}) {
    const ProcResult r = run_fit(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": [" << r.err << "]";
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  }
  // The issue's invalid options (once accepted: a negative window, a NaN threshold, a negative
  // reduction, a window of 1 ns that reported "gap 0 -> 0"): one line naming option and value.
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"--replay-window -1", "--replay-window: '-1' is outside [0.001, 1000] (or 0 for the default)"},
      {"--replay-window 1e-9", "--replay-window: '1e-9' is outside [0.001, 1000]"},
      {"--score-threshold nan", "--score-threshold: 'nan' is not a finite number"},
      {"--min-gap-reduction -5", "--min-gap-reduction: '-5' is outside [0, 0.99]"},
      {"--filter-half-width inf", "--filter-half-width: 'inf' is not a finite number"},
      {"--time-stamp-error -1e-6", "--time-stamp-error: '-1e-6' is outside ["},
      {"--time-stamp-error nan", "--time-stamp-error: 'nan' is not a finite number"},
  };
  for (const auto& [option, message] : bad) {
    const ProcResult r = run_fit("--scenario x.yaml --data y.csv --out z " + option);
    EXPECT_EQ(r.code, 2) << option << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << option << ": [" << r.err << "]";
    EXPECT_EQ(r.err.rfind("error: " + message, 0), 0u) << r.err;
    EXPECT_FALSE(fs::exists("z"));
  }
  // --out naming an unrelated folder is refused before anything is loaded: the data file need
  // not even exist for the message to be about the folder.
  fs::create_directories(scratch() / "mine");
  std::ofstream(scratch() / "mine" / "keep.txt") << "mine\n";
  const ProcResult r = run_fit("--scenario " + model_scenario().string() + " --data " +
                               (scratch() / "not_there.csv").string() + " --out " + (scratch() / "mine").string());
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("mine"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("not_there.csv"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(scratch() / "mine" / "keep.txt"), "mine\n");
}

TEST(FitCli, WindowsThatHoldTooFewSamplesAreRefused) {
  // At 1 kHz a replay window of 5 ms holds 6 samples: the start-state correction (offset and
  // slope) then fits away any gap (the issue's "gap 0 -> 0" at --replay-window 1e-9); a filter
  // half-width below 2 periods averages nothing. Both are refused with the record's period.
  const std::string data = csv("t,x,u", good_rows(2000));
  expect_data_error(
      "short_window.csv", data,
      {"short_window.csv", "--replay-window 0.005 s spans fewer than 10 sample periods (0.001 s)", "at least 0.01 s"},
      "--replay-window 0.005");
  expect_data_error("short_filter.csv", data,
                    {"short_filter.csv", "--filter-half-width 0.0015 s is shorter than 2 sample periods (0.001 s)"},
                    "--filter-half-width 0.0015");
}

TEST(FitCli, FinitePositionOutliersTooLargeForAFiniteFitAreNamed) {
  // A position of 1e308 m made the motion estimate NaN, blamed on "plant.initial.bristle = -nan"
  // after two lines of Ceres logging; one of 1e200 m gave a findings.json with null (inf) gaps.
  // Both: exit 2, one line naming the sample (found by the fuzz suite, seed 30055).
  for (const std::string big : {"1e308", "1e200"}) {
    auto rows = good_rows(2000);
    rows[700] = "0.7," + big + ",0.05";
    expect_data_error(
        "outlier_" + big + ".csv", csv("t,x,u", rows),
        {"outlier_" + big + ".csv", "at t = 0.7 s", "is the position column in metres and free of outliers?"});
  }
}

TEST(FitCli, CorruptLcmLog) {
  // 4 kB of random bytes: not an LCM log (no sync word at event 0).
  std::mt19937 rng(12345);
  std::string bytes(4096, '\0');
  for (auto& c : bytes) c = static_cast<char>(rng() & 0xff);
  expect_data_error("garbage.lcm", bytes, {"garbage.lcm", "corrupt LCM log"});
  // A file holding only part of one event header: a log cut inside its first event.
  expect_data_error("stub.lcmlog", std::string("\xED\xA1\xDA\x01\x00\x00", 6),
                    {"stub.lcmlog", "no complete step", "the log ends inside an event (byte 0, its last 6 bytes"});
  // ... and the same bytes not starting like an event: corrupt.
  expect_data_error("stub2.lcmlog", std::string("\xED\xA1\xDA\x02\x00\x00", 6), {"stub2.lcmlog", "corrupt LCM log"});
}

TEST(FitCli, MalformedScenario) {
  const std::string model = slurp(model_scenario());
  const fs::path scen = write_file("bad_model.yaml", model + "plnt: {}\n");
  const fs::path data = write_file("fine.csv", csv("t,x,u", good_rows(100)));
  const fs::path out = scratch() / "out_bad_model";
  const ProcResult r =
      run_fit("--scenario " + scen.string() + " --data " + data.string() + " --out " + out.string() + " -q --no-plots");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("bad_model.yaml"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("plnt: unknown key"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  // A scenario file that does not exist.
  const ProcResult m = run_fit("--scenario " + (scratch() / "nope.yaml").string() + " --data " + data.string() +
                               " --out " + out.string() + " -q");
  EXPECT_EQ(m.code, 2) << m.err;
  EXPECT_EQ(std::count(m.err.begin(), m.err.end(), '\n'), 1) << m.err;
  EXPECT_NE(m.err.find("nope.yaml: cannot read the scenario file"), std::string::npos) << m.err;
}

// The scenario of the good run: scenarios/fit/model.yaml cut to 4 s (the reference's first 4 s:
// it goes on to 10 s), the reference named by its absolute path, and `effects` (YAML lines under
// plant, "" for none) added.
std::string short_scenario(const std::string& effects) {
  std::string s = slurp(model_scenario());
  const auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = s.find(from);
    if (at == std::string::npos) throw std::runtime_error("model.yaml has no '" + from + "'");
    s.replace(at, from.size(), to);
  };
  replace("duration: 10.0", "duration: 4.0");
  replace("file: rich_reference.csv", "file: " + (kScenarios / "rich_reference.csv").string());
  replace("controller:", effects + "controller:");
  return s;
}

// 4 s of data of the model plus a 15 N constant force (feeddrive-sim, measured position).
fs::path simulated_data() {
  static const fs::path data = [] {
    const fs::path truth = write_file("truth4.yaml", short_scenario("  effects:\n    constant_force: {force: 15.0}\n"));
    const fs::path out = scratch() / "sim_truth";
    const ProcResult r = run(kSim, truth.string() + " --out " + out.string() + " --no-plots --quiet");
    if (r.code != 0) throw std::runtime_error("feeddrive-sim failed: " + r.err);
    return out / "timeseries.csv";
  }();
  return data;
}

TEST(FitCli, FindsAConstantForceEndToEnd) {
  const fs::path model = write_file("model4.yaml", short_scenario(""));
  const fs::path data = simulated_data();
  const fs::path out = scratch() / "fit_out";
  const ProcResult r = run_fit("--scenario " + model.string() + " --data " + data.string() + " --out " + out.string() +
                               " --position-column x_measured --no-plots -q");
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  // -q: nothing but (at most) warnings on stderr.
  EXPECT_EQ(r.err.find("error"), std::string::npos) << r.err;

  for (const char* f : {"findings.json", "model.fitted.yaml", "report.md"}) EXPECT_TRUE(fs::exists(out / f)) << f;
  std::ifstream js(out / "findings.json");
  const auto j = nlohmann::json::parse(js);
  ASSERT_TRUE(j.contains("effects") && j["effects"].is_array() && !j["effects"].empty()) << j.dump(2);
  const auto& first = j["effects"][0];
  EXPECT_EQ(first["name"].get<std::string>(), "constant_force") << j.dump(2);
  // 20 %: with 4 s of closed-loop data (20 nm noise, 50 nm quantization) the force estimate is
  // good to well under 1 N; 20 % (3 N) still tells a found 15 N force from a partial one absorbed
  // by another effect, without being flaky.
  const double f = first["parameters"]["force"].get<double>();
  EXPECT_NEAR(f, 15.0, 0.2 * 15.0) << j.dump(2);
  // The constant force is the whole discrepancy, so adding it must remove most of the replay gap;
  // a factor 5 leaves room for noise and the short record, and still fails if it only half-fits.
  const double g0 = j["gap_initial"].get<double>(), g1 = j["gap_final"].get<double>();
  EXPECT_GT(g0, 0.0);
  EXPECT_LT(g1, g0 / 5.0) << "gap_initial " << g0 << ", gap_final " << g1;
  EXPECT_LE(first["gap_after"].get<double>(), first["gap_before"].get<double>());

  // The fitted model is a scenario feeddrive-sim accepts, with the effect switched on.
  feeddrive::sim::Scenario fitted;
  ASSERT_NO_THROW(fitted = feeddrive::sim::load_scenario((out / "model.fitted.yaml").string()));
  EXPECT_TRUE(fitted.plant.effects.constant_force.enabled);
  // Same 20 % as above: the YAML carries the fitted value.
  EXPECT_NEAR(fitted.plant.effects.constant_force.force, 15.0, 0.2 * 15.0);
  EXPECT_NEAR(fitted.plant.effects.constant_force.force, f, 1e-3 * std::abs(f)) << "the YAML holds the JSON value";

  // --out on an existing unrelated folder: refused, non-zero exit, one line, the folder untouched.
  const fs::path precious = scratch() / "precious";
  fs::create_directories(precious);
  std::ofstream(precious / "thesis.tex") << "keep me";
  const ProcResult p = run_fit("--scenario " + model.string() + " --data " + data.string() + " --out " +
                               precious.string() + " --position-column x_measured --no-plots -q");
  EXPECT_NE(p.code, 0);
  EXPECT_EQ(p.code, 2) << p.err;
  EXPECT_EQ(std::count(p.err.begin(), p.err.end(), '\n'), 1) << p.err;
  EXPECT_NE(p.err.find(precious.string()), std::string::npos) << p.err;
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(precious)) left.push_back(e.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{"thesis.tex"});
  EXPECT_EQ(slurp(precious / "thesis.tex"), "keep me");

  // A folder with a fake findings.json (even valid JSON) is not an output: refused, untouched.
  const fs::path fake = scratch() / "fake";
  fs::create_directories(fake);
  std::ofstream(fake / "findings.json") << "{}";
  std::ofstream(fake / "notes.txt") << "mine";
  const ProcResult fk = run_fit("--scenario " + model.string() + " --data " + data.string() + " --out " +
                                fake.string() + "/ --position-column x_measured --no-plots -q");
  EXPECT_EQ(fk.code, 2) << fk.err;
  EXPECT_EQ(std::count(fk.err.begin(), fk.err.end(), '\n'), 1) << fk.err;
  EXPECT_NE(fk.err.find("not a feeddrive output"), std::string::npos) << fk.err;
  EXPECT_EQ(slurp(fake / "notes.txt"), "mine");
  EXPECT_EQ(slurp(fake / "findings.json"), "{}");

  // An earlier feeddrive-fit output (it has the marker) that holds a file of the user's is
  // refused before any work, the file kept; without it, the output is replaced, also as "DIR/".
  EXPECT_TRUE(fs::exists(out / ".feeddrive-output"));
  std::ofstream(out / "notes.txt") << "mine";
  const std::string again_args = "--scenario " + model.string() + " --data " + data.string() + " --out " +
                                 out.string() + "/ --position-column x_measured --no-plots -q --max-effects 1";
  const ProcResult kept = run_fit(again_args);
  EXPECT_EQ(kept.code, 2) << kept.err;
  EXPECT_EQ(std::count(kept.err.begin(), kept.err.end(), '\n'), 1) << kept.err;
  EXPECT_NE(kept.err.find("holds 'notes.txt', which feeddrive did not write"), std::string::npos) << kept.err;
  EXPECT_EQ(slurp(out / "notes.txt"), "mine");
  fs::remove(out / "notes.txt");
  const ProcResult again = run_fit(again_args);
  EXPECT_EQ(again.code, 0) << again.err;
  EXPECT_TRUE(fs::exists(out / "findings.json"));
  for (const auto& e : fs::directory_iterator(scratch()))
    EXPECT_EQ(e.path().filename().string().find(".fit_out."), std::string::npos) << "left behind: " << e.path();
}

// Quoted for the shell of std::system: any text is one word.
std::string sh(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// --out is checked first: every value that cannot be written is refused with exit 2 and one line
// naming it, before the scenario or the data are read (the data file does not even exist).
TEST(FitCli, UnwritableOutRefusedBeforeAnyWork) {
  const fs::path base = scratch() / "unwritable";
  fs::create_directories(base);
  std::ofstream(base / "file") << "a file";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "empty path"},
      {"/", "names no folder"},
      {".", "names no folder"},
      {(base / "file" / "out").string(), "is not a folder"},
      {(base / std::string(300, 'n')).string(), "too long"},
  };
  for (const auto& [value, why] : cases) {
    const ProcResult r = run_fit("--scenario " + model_scenario().string() + " --data " +
                                 (scratch() / "not_there.csv").string() + " --out " + sh(value) + " -q");
    EXPECT_EQ(r.code, 2) << value << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("error: --out " + (value.empty() ? std::string("\"\"") : value.substr(0, 40)), 0), 0u)
        << r.err;
    EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("not_there.csv"), std::string::npos) << r.err;
  }
  EXPECT_EQ(slurp(base / "file"), "a file");
}

// File names, column names and --out values are never gnuplot or shell code: a fit with plots
// on data, a model and an output folder named to run a command succeeds and runs nothing.
TEST(FitCli, NamesAreNeverRunAsCommands) {
  const fs::path base = scratch() / "inject";
  fs::create_directories(base);
  const fs::path mark = base / "MARK";
  const fs::path model = base / "m'; system 'touch MARK'; print '.yaml";
  std::ofstream(model) << short_scenario("");
  // the data with its position column renamed
  std::string data = slurp(simulated_data());
  const auto at = data.find("x_measured");
  ASSERT_NE(at, std::string::npos);
  data.replace(at, 10, "pos'; system 'touch MARK'; print '");
  const fs::path data_file = base / "d'; system 'touch MARK'; print '.csv";
  std::ofstream(data_file) << data;
  const fs::path out = base / "o'; touch MARK; echo '";
  // in base, where a relative "touch MARK" would land
  const std::string args = "--scenario " + sh(model.string()) + " --data " + sh(data_file.string()) + " --out " +
                           sh(out.string()) + " --position-column " + sh("pos'; system 'touch MARK'; print '") +
                           " --max-effects 1 -q";
  const ProcResult r = run("sh", "-c " + sh("cd " + sh(base.string()) + " && exec " + kFit + " " + args));
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  for (const char* f : {"findings.json", "report.md", "replay.png", "gap.png", "plots.gp"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  EXPECT_FALSE(fs::exists(mark));
  EXPECT_FALSE(fs::exists(out / "MARK"));
  EXPECT_FALSE(fs::exists(fs::path(FEEDDRIVE_BINARY_DIR) / "MARK"));
}

}  // namespace

// ---- issue 20: verdicts, the user's own data and units, sanity before fitting ----------------

namespace issue20 {

// The columns of a CSV file (comma-separated, with a header), by name.
std::map<std::string, std::vector<std::string>> columns_of(const fs::path& file) {
  std::istringstream in(slurp(file));
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  {
    std::istringstream h(line);
    for (std::string c; std::getline(h, c, ',');) names.push_back(c);
  }
  std::map<std::string, std::vector<std::string>> out;
  while (std::getline(in, line)) {
    std::istringstream r(line);
    std::size_t i = 0;
    for (std::string c; std::getline(r, c, ',') && i < names.size(); ++i) out[names[i]].push_back(c);
  }
  return out;
}

double num(const std::string& s) { return std::stod(s); }

// A CSV from the CI record (simulated_data(): feeddrive-sim, a 15 N constant force): columns
// `names`, each made by `make(row)`; `sep` between fields.
std::string derived(const std::vector<std::string>& names,
                    const std::function<std::vector<std::string>(const std::map<std::string, std::vector<std::string>>&,
                                                                 std::size_t)>& make,
                    const std::string& sep = ",") {
  const auto cols = columns_of(simulated_data());
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i) s += (i ? sep : "") + names[i];
  s += "\n";
  for (std::size_t k = 0; k < cols.at("t").size(); ++k) {
    const auto f = make(cols, k);
    if (f.empty()) continue;  // a row left out (e.g. a record decimated)
    for (std::size_t i = 0; i < f.size(); ++i) s += (i ? sep : "") + f[i];
    s += "\n";
  }
  return s;
}

std::string g17(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

// The CI record as "t,x,force_N", each row (k, t, x, force) as `edit` leaves it; a row for which
// it returns false is left out (a gap, every other row).
std::string edited(const std::function<bool(std::size_t, double&, double&, double&)>& edit) {
  return derived({"t", "x", "force_N"}, [&](const auto& c, std::size_t k) {
    double t = num(c.at("t")[k]), x = num(c.at("x_measured")[k]), f = num(c.at("f_thrust")[k]);
    if (!edit(k, t, x, f)) return std::vector<std::string>{};
    return std::vector<std::string>{g17(t), g17(x), g17(f)};
  });
}

nlohmann::json findings(const fs::path& out) {
  std::ifstream js(out / "findings.json");
  return nlohmann::json::parse(js);
}

fs::path model4() { return write_file("model4.yaml", short_scenario("")); }

}  // namespace issue20

// Every named effect shrinks the replay gap (the 5 % rule it was chosen by), also after the model
// form is recalibrated with it (issue 20's review: a position 10x too small, as following a
// cm -> mm hint gives, had presliding chosen for its replay and named at 114.5 -> 115.8 um once
// recalibrated). The CI record with its position divided by 10: whatever is named, each accepted
// step's gap after is below its gap before.
TEST(FitVerdict, ANamedEffectNeverWidensTheGap) {
  using namespace issue20;
  const fs::path data = write_file("pos_tenth.csv", edited([](std::size_t, double&, double& x, double&) {
                                     x /= 10.0;
                                     return true;
                                   }));
  const fs::path out = scratch() / "pos_tenth";
  const ProcResult r = run_fit("--scenario " + model4().string() + " --data " + data.string() + " --out " +
                               out.string() + " --no-plots -q");
  ASSERT_TRUE(r.code == 0 || r.code == 3) << r.err << r.out;
  const auto j = findings(out);
  int accepted = 0;
  for (const auto& st : j["steps"]) {
    if (!st["accepted"].get<bool>()) continue;
    ++accepted;
    EXPECT_LT(st["gap_after_m"].get<double>(), st["gap_before_m"].get<double>()) << st["verdict"];
  }
  EXPECT_GT(accepted, 0) << j["conclusion"];  // the record's 15 N force (seen 10x off) names something
}

// "Explained": the 15 N constant force takes the gap to the noise floor of the 50 nm / 20 nm
// encoder (the gap's allowance, 3x: here 1.8x) and the force residual within its allowance (3x:
// here 1.12x); every parameter has its interval.
TEST(FitVerdict, ExplainedNoDiscrepancyAndTheirExitCodes) {
  using namespace issue20;
  const fs::path out = scratch() / "verdict_explained";
  const ProcResult r = run_fit("--scenario " + model4().string() + " --data " + simulated_data().string() + " --out " +
                               out.string() + " --position-column x_measured --no-plots -q");
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  const auto j = findings(out);
  EXPECT_EQ(j["verdict"], "explained") << j["conclusion"];
  EXPECT_EQ(j["exit_code"], 0);
  EXPECT_GT(j["noise_floor"]["gap_m"].get<double>(), 0.0);
  EXPECT_LE(j["gap_final"].get<double>(), 3.0 * j["noise_floor"]["gap_m"].get<double>());
  EXPECT_LE(j["force_residual_rms_final_N"].get<double>(),
            j["noise_floor"]["force_factor"].get<double>() * j["noise_floor"]["force_rms_N"].get<double>());
  // the force's 95 % interval: finite and below 1 N on 4 s of 1 kHz data (the fit gives ~15 +- 0.1 N)
  const double ci = j["effects"][0]["ci95"]["force"].get<double>();
  EXPECT_GT(ci, 0.0);
  EXPECT_LT(ci, 1.0);
  EXPECT_NE(r.out.find("explained: found 1 effect(s): constant_force"), std::string::npos) << r.out;
  // "No discrepancy": the model is the drive (same 4 s, no hidden force).
  const fs::path free_data = [] {
    const fs::path truth = write_file("free4.yaml", short_scenario(""));
    const fs::path o = scratch() / "sim_free";
    const ProcResult s = run(kSim, truth.string() + " --out " + o.string() + " --no-plots --quiet");
    if (s.code != 0) throw std::runtime_error("feeddrive-sim failed: " + s.err);
    return o / "timeseries.csv";
  }();
  const fs::path out2 = scratch() / "verdict_free";
  const ProcResult f = run_fit("--scenario " + model4().string() + " --data " + free_data.string() + " --out " +
                               out2.string() + " --position-column x_measured --no-plots -q");
  ASSERT_EQ(f.code, 0) << f.err << f.out;
  const auto jf = findings(out2);
  EXPECT_EQ(jf["verdict"], "no_discrepancy") << jf["conclusion"];
  EXPECT_TRUE(jf["effects"].empty());
  EXPECT_NE(jf["conclusion"].get<std::string>().find("within its noise"), std::string::npos);
  // The same record against a model without a sensor: the floor is a guess from the record (its
  // smallest position step), so no all-clear: unexplained, exit 3, saying what would settle it.
  const fs::path out3 = scratch() / "verdict_no_sensor";
  const ProcResult n =
      run_fit("--scenario " + model4().string() + " --data " + free_data.string() + " --out " + out3.string() +
              " --position-column x_measured --no-plots -q --set plant.sensor.quantization=0"
              " --set plant.sensor.noise_stddev=0");
  ASSERT_EQ(n.code, 3) << n.err << n.out;
  const auto jn = findings(out3);
  EXPECT_EQ(jn["verdict"], "unexplained") << jn["conclusion"];
  EXPECT_NE(jn.dump().find("give plant.sensor"), std::string::npos) << jn.dump();
  EXPECT_EQ(jn["conclusion"].get<std::string>().find("within its noise"), std::string::npos);
}

// "Within" is at most 3x the floor for both the gap and the force residual (verdict.hpp: an
// exact model with friction reaches 2x at reversals); a record above either is not within.
TEST(FitVerdict, WithinIsTheAllowanceOfEachFloor) {
  using namespace feeddrive::fit;
  NoiseFloor f;
  f.force = 0.06;
  f.gap = 25e-9;
  f.force_factor = kForceAllowance;
  f.gap_factor = kGapAllowance;
  EXPECT_TRUE(within_floor(f, 74e-9, 0.17));
  EXPECT_FALSE(within_floor(f, 76e-9, 0.06));  // the gap above 3x: not within, whatever the force
  EXPECT_FALSE(within_floor(f, 25e-9, 0.19));  // the force above 3x: not within, whatever the gap
}

// The independent generator (fd-drivegen), as a user would run it: files on disk, the CLI.
fs::path drivegen(const std::string& name, const std::string& args) {
  const fs::path dir = scratch() / name;
  const ProcResult g = run(std::string(FEEDDRIVE_BINARY_DIR) + "/bin/fd-drivegen",
                           args.substr(0, args.find(' ')) + " " + dir.string() + args.substr(args.find(' ')));
  if (g.code != 0) throw std::runtime_error("fd-drivegen failed: " + g.err);
  return dir;
}

// fd-drivegen ARGS into scratch()/gen_NAME, then feeddrive-fit on its model.yaml and data.csv
// into scratch()/NAME: the run and its findings.json (empty if none was written).
struct GeneratedFit {
  ProcResult run;
  nlohmann::json findings;
  fs::path out;
};
GeneratedFit generate_and_fit(const std::string& name, const std::string& args) {
  const fs::path dir = drivegen("gen_" + name, args);
  GeneratedFit g{run_fit("--scenario " + (dir / "model.yaml").string() + " --data " + (dir / "data.csv").string() +
                         " --out " + (scratch() / name).string() + " --no-plots -q"),
                 {},
                 scratch() / name};
  if (fs::exists(g.out / "findings.json")) g.findings = issue20::findings(g.out);
  return g;
}

// Presliding resolved only at its fitted value is not named (workflow.cpp, unresolved_presliding):
// fd-drivegen 8484012729 is effect-free (seed 4242's record 3 of issue 20's mix) with a 65 nm
// encoder; its friction's other form left a gap the bristles took 9 % off at a deflection of
// 0.080 um, whose 95 % interval reaches 0.051 um, below one count. Nothing is named, and the
// presliding candidate is passed over for it.
TEST(FitVerdict, PreslidingResolvedOnlyAtItsFittedValueIsNotNamed) {
  const GeneratedFit g = generate_and_fit("presliding_unresolved", "8484012729 10");
  ASSERT_TRUE(g.run.code == 0 || g.run.code == 3) << g.run.err << g.run.out;
  EXPECT_TRUE(g.findings["effects"].empty()) << g.findings["conclusion"];
  std::string why;
  for (const auto& st : g.findings["steps"])
    for (const auto& c : st["ranking"])
      if (c["name"] == "presliding") why += c["passed_over"].get<std::string>() + "\n";
  EXPECT_NE(why.find("within its 95 % interval, below the sensor's resolution"), std::string::npos) << why;
}

// "Unexplained": a 49.5 mm ripple over 79 mm of travel (1.6 periods) and a 30 % mass error. The
// ripple cannot be resolved; the gap stays at ~23 um against a 0.04 um floor: exit 3, and the
// report says where, what it resembles, why not and what record would settle it.
TEST(FitVerdict, UnexplainedSaysWhatWouldSettleItAndExitsThree) {
  using namespace issue20;
  const GeneratedFit g = generate_and_fit("verdict_unexplained", "5 10 cogging_ripple,mass_error periods=1.6");
  const ProcResult& r = g.run;
  ASSERT_EQ(r.code, 3) << r.err << r.out;
  const auto& j = g.findings;
  EXPECT_EQ(j["verdict"], "unexplained");
  EXPECT_EQ(j["exit_code"], 3);
  EXPECT_GT(j["gap_final"].get<double>(), 3.0 * j["noise_floor"]["gap_m"].get<double>());
  std::string all;
  for (const auto& u : j["unexplained"]) all += u.get<std::string>() + "\n";
  EXPECT_NE(all.find("where: the force residual concentrates in"), std::string::npos) << all;
  EXPECT_NE(all.find("resembles cogging_ripple"), std::string::npos) << all;
  EXPECT_NE(all.find("fewer than two periods"), std::string::npos) << all;
  EXPECT_NE(all.find("a force periodic in position, pitch about"), std::string::npos) << all;
  EXPECT_NE(all.find("record a travel of at least 3 periods"), std::string::npos) << all;
  EXPECT_EQ(j["conclusion"].get<std::string>().find("within its noise"), std::string::npos);
  EXPECT_NE(slurp(g.out / "report.md").find("## Unexplained discrepancy"), std::string::npos);
}

// A ripple too short for the filter at the record's speed (issue 20's review): a 3 mm, 5 N cogging
// on the model's 10 s record passes at up to 100 Hz at 297 mm/s, beyond what the 10 ms filter
// resolves. Its candidate cannot score (it fits an aliased 4.3 mm pitch, implausibly short), yet
// it takes 3.7 % off the residual, more than its five parameters take from noise: the unexplained
// verdict names it as what the rest resembles and says to record slower moves, where it said "no
// candidate of the vocabulary reduces the residual".
TEST(FitVerdict, ARippleTooShortForTheFilterIsWhatTheRestResembles) {
  using namespace issue20;
  const fs::path sim = scratch() / "sim_short_pitch";
  ASSERT_EQ(
      run(kSim, model_scenario().string() + " --set plant.effects.cogging_ripple.pitch=0.003 --set " +
                    "plant.effects.cogging_ripple.cogging_amplitude=5.0 --out " + sim.string() + " --no-plots --quiet")
          .code,
      0);
  const fs::path out = scratch() / "short_pitch";
  const ProcResult r =
      run_fit("--scenario " + model_scenario().string() + " --data " + (sim / "timeseries.csv").string() +
              " --position-column x_measured --out " + out.string() + " --no-plots -q");
  ASSERT_EQ(r.code, 3) << r.err << r.out;
  std::string all;
  const auto j = findings(out);
  for (const auto& u : j["unexplained"]) all += u.get<std::string>() + "\n";
  EXPECT_NE(all.find("resembles cogging_ripple"), std::string::npos) << all;
  EXPECT_NE(all.find("faster than the filter resolves"), std::string::npos) << all;
  EXPECT_NE(all.find("record the moves at most"), std::string::npos) << all;
  EXPECT_EQ(all.find("no candidate of the vocabulary"), std::string::npos) << all;
  // no ripple at a longer pitch it does not have (issue 20's review: a 4 mm cogging was named at
  // 10.3 mm once the periodogram stopped at the shortest resolved pitch)
  EXPECT_TRUE(j["effects"].empty()) << j["conclusion"];
}

// The model's own record (scenarios/fit/model.yaml) with `sets` added to the drive, fitted with
// the model and `fit_sets`: the fit's result and its findings.json.
struct SimFit {
  ProcResult r;
  nlohmann::json j;
};
SimFit sim_and_fit(const std::string& name, const std::string& sets, const std::string& fit_sets = "") {
  const fs::path sim = scratch() / ("sim_" + name);
  const ProcResult s =
      run(kSim, model_scenario().string() + " " + sets + " --out " + sim.string() + " --no-plots --quiet");
  EXPECT_EQ(s.code, 0) << s.err;
  const fs::path out = scratch() / name;
  SimFit f;
  f.r = run_fit("--scenario " + model_scenario().string() + " " + fit_sets + " --data " +
                (sim / "timeseries.csv").string() + " --position-column x_measured --out " + out.string() +
                " --no-plots -q");
  if (fs::exists(out / "findings.json")) f.j = issue20::findings(out);
  return f;
}

// A true viscous friction of 10 N s/m, 3 N at the 296 mm/s peak, 2.5 % of the model's 120 N
// friction level: named and recovered (issue 20's review of a rule, since removed, that took a
// viscous force under 3 % of the friction level for the friction's form, refused this one at
// score 2751 and named a 1 N Coulomb friction in its place). 20 %: the tolerance of a level
// (docs/fit.md, "What the tests establish").
TEST(FitVerdict, ASmallTrueViscousFrictionIsNamedNotACoulombFriction) {
  const SimFit f = sim_and_fit("visc10", "--set plant.effects.viscous_friction.viscous=10");
  ASSERT_EQ(f.r.code, 0) << f.r.err << f.r.out;
  EXPECT_EQ(f.j["verdict"], "explained");
  bool viscous = false;
  for (const auto& e : f.j["effects"]) {
    EXPECT_NE(e["name"], "coulomb_friction") << f.j["conclusion"];
    if (e["name"] == "viscous_friction") {
      viscous = true;
      EXPECT_NEAR(e["parameters"]["viscous"].get<double>(), 10.0, 2.0);
    }
  }
  EXPECT_TRUE(viscous) << f.j["conclusion"];
}

// A reluctance ripple is named from 1 % of the thrust (plausibility.hpp, kLeastMassChange); one
// whose fitted amplitude is below only by its uncertainty is tentative (issue 20's point 2; the
// review: 0.9986 % +- 0.008 %, score 2325, was refused outright, "1 % is below 1 %"). One of 0.8 %
// is refused: the step says the candidate is significant but passed over (not "no significant
// effect" at score 2109), and what would settle it is a thrust measured over position, not a
// longer record, which cannot change an amplitude limit.
TEST(FitVerdict, AReluctanceRippleAtItsLeastAmplitudeIsTentative) {
  const std::string ripple =
      "--set plant.effects.reluctance_ripple.pitch=0.02 --set "
      "plant.effects.reluctance_ripple.reluctance_phase=0.5 --set "
      "plant.effects.reluctance_ripple.reluctance_amplitude=";
  const SimFit at = sim_and_fit("rel0995", ripple + "0.00995");
  ASSERT_TRUE(at.r.code == 0 || at.r.code == 3) << at.r.err << at.r.out;
  bool named = false;
  for (const auto& e : at.j["effects"])
    if (e["name"] == "reluctance_ripple") {
      named = true;
      EXPECT_TRUE(e["tentative"].get<bool>());
      EXPECT_NE(e["caveat"].get<std::string>().find("reaches the 1 % limit"), std::string::npos) << e["caveat"];
    }
  EXPECT_TRUE(named) << at.j["conclusion"];

  const SimFit below = sim_and_fit("rel08", ripple + "0.008");
  ASSERT_EQ(below.r.code, 3) << below.r.err << below.r.out;
  std::string steps, all;
  for (const auto& st : below.j["steps"]) steps += st["verdict"].get<std::string>() + "\n";
  for (const auto& u : below.j["unexplained"]) all += u.get<std::string>() + "\n";
  EXPECT_NE(steps.find("nothing named: the best candidate, reluctance_ripple"), std::string::npos) << steps;
  EXPECT_EQ(steps.find("no significant effect: the best candidate, reluctance_ripple"), std::string::npos) << steps;
  EXPECT_NE(all.find("measure the thrust at rest at several positions"), std::string::npos) << all;
}

// The exact model of a static-friction drive: within the noise floor as given, so "no
// discrepancy" (issue 20's point 1). The review found it "unexplained" at 0.143 um, 5.8x the floor:
// the model form's refit on the force residual (eps 0.01 -> 0.041 mm/s) lengthened the replay gap
// from 0.039 um, and was kept. Now, with nothing named, a form refit that lengthens the gap is not
// kept (workflow.cpp, form_as_given).
TEST(FitVerdict, TheExactModelOfAStaticFrictionDriveShowsNoDiscrepancy) {
  const SimFit f =
      sim_and_fit("exact_static", "--set plant.friction.model=static", "--set plant.friction.model=static");
  ASSERT_EQ(f.r.code, 0) << f.r.err << f.r.out;
  EXPECT_EQ(f.j["verdict"], "no_discrepancy") << f.j["conclusion"];
  EXPECT_TRUE(f.j["effects"].empty()) << f.j["conclusion"];
}

// A plant.sensor noise the record contradicts is taken at the most the record allows (fit/verdict.hpp,
// "What the record allows"): the CI record (20 nm noise, 50 nm steps: sigma_x = 24.7 nm) fitted with
// a scenario that claims 1 um of noise. Its floor would be 40x too high; an all-clear on it could
// hide a force 40x larger than the record shows. The record's positions at speed scatter by about
// sigma_x (up to 1.3x over for a uniform rather than Gaussian error), so the noise is taken below
// 3 x 1.3 x 24.7 = 96 nm and above the true 20 nm.
TEST(FitVerdict, ASensorNoiseTheRecordContradictsIsTakenAtItsBound) {
  using namespace issue20;
  std::string yaml = short_scenario("");
  const auto at = yaml.find("noise_stddev: 2.0e-8");
  ASSERT_NE(at, std::string::npos);
  yaml.replace(at, 20, "noise_stddev: 1.0e-6");
  const fs::path scenario = write_file("noisy_sensor.yaml", yaml);
  const fs::path out = scratch() / "noisy_sensor";
  const ProcResult r = run_fit("--scenario " + scenario.string() + " --data " + simulated_data().string() +
                               " --position-column x_measured --out " + out.string() + " --no-plots -q");
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  const auto j = findings(out);
  const auto& f = j["noise_floor"];
  EXPECT_DOUBLE_EQ(f["noise_given_m"].get<double>(), 1e-6);
  EXPECT_GT(f["noise_m"].get<double>(), 20e-9);
  EXPECT_LT(f["noise_m"].get<double>(), 96e-9);
  EXPECT_NE(j["conclusion"].get<std::string>().find("plant.sensor's noise 1e+03 nm taken as"), std::string::npos)
      << j["conclusion"];
  // the 15 N constant force of the record is found as it is with the true sensor
  EXPECT_EQ(j["effects"].size(), 1u) << j["conclusion"];
  // A 5 um encoder claimed for the record's 50 nm steps (issue 20's review: a 0.8 % mass error
  // got "no discrepancy" at a 1.4 um floor): the quantum is taken as the record's smallest step.
  const auto q = yaml.find("quantization: 5.0e-8");
  ASSERT_NE(q, std::string::npos);
  yaml.replace(q, 20, "quantization: 5.0e-6");
  const fs::path out_q = scratch() / "coarse_sensor";
  const ProcResult rq =
      run_fit("--scenario " + write_file("coarse_sensor.yaml", yaml).string() + " --data " + simulated_data().string() +
              " --position-column x_measured --out " + out_q.string() + " --no-plots -q");
  ASSERT_EQ(rq.code, 0) << rq.err << rq.out;
  const auto jq = findings(out_q);
  EXPECT_DOUBLE_EQ(jq["noise_floor"]["quantization_given_m"].get<double>(), 5e-6);
  EXPECT_NEAR(jq["noise_floor"]["quantization_m"].get<double>(), 50e-9, 1e-9);  // the record's step
  EXPECT_LT(jq["noise_floor"]["gap_m"].get<double>(), 0.1e-6) << jq["conclusion"];
  // A 5 nm encoder with 2 nm noise declared for the record's 50 nm steps: the floor is 10x too low, and the
  // unexplained verdict says so (it blamed friction), rather than pass a claim the record refutes.
  std::string fine = short_scenario("");
  fine.replace(fine.find("quantization: 5.0e-8"), 20, "quantization: 5.0e-9");
  fine.replace(fine.find("noise_stddev: 2.0e-8"), 20, "noise_stddev: 2.0e-9");
  const fs::path out_f = scratch() / "fine_sensor";
  const ProcResult rf =
      run_fit("--scenario " + write_file("fine_sensor.yaml", fine).string() + " --data " + simulated_data().string() +
              " --position-column x_measured --out " + out_f.string() + " --no-plots -q");
  ASSERT_EQ(rf.code, 3) << rf.err << rf.out;
  std::string lines;
  const auto jf = findings(out_f);
  for (const auto& u : jf["unexplained"]) lines += u.get<std::string>() + "\n";
  EXPECT_NE(lines.find("smallest position step 50 nm is 10 times plant.sensor.quantization (5 nm)"), std::string::npos)
      << lines;
}

// A grinding force whose stiffness the record does not identify at first (issue 20's review):
// fd-drivegen 301's grinding force (C = 649.7 N s/m, C/ke = 3.27 ms, contact at 64.2 mm) fits
// alone with C/ke run off to 1e-17 ms, below the 1 ms sample period. It was refused (score 2142)
// and a viscous friction named in its place at 78 um. Now it is named first, tentative and held at
// C/ke = one sample period; the later joint refits move C/ke to 3.1 ms (measured), which passes
// every limit: at the end it is no longer tentative. Damping and contact within the sweep's
// tolerances (20 % and 2 %; measured 0.2 %), C/ke within 20 % of the truth.
TEST(FitVerdict, AGrindingForceWithoutAnIdentifiedStiffnessIsNamedFirst) {
  using namespace issue20;
  const GeneratedFit g = generate_and_fit("grinding_tentative", "301 10 grinding_force grinding");
  ASSERT_TRUE(g.run.code == 0 || g.run.code == 3) << g.run.err << g.run.out;
  const auto& e = g.findings["effects"];
  ASSERT_FALSE(e.empty()) << g.findings["conclusion"];
  EXPECT_EQ(e[0]["name"], "grinding_force") << g.findings["conclusion"];
  EXPECT_FALSE(e[0]["tentative"].get<bool>()) << e[0]["caveat"];
  const double C = e[0]["parameters"]["damping"].get<double>();
  EXPECT_NEAR(C, 649.712, 0.2 * 649.712);
  EXPECT_NEAR(e[0]["parameters"]["contact_position"].get<double>(), 0.0642374, 0.02 * 0.0642374);
  EXPECT_NEAR(C / e[0]["parameters"]["stiffness"].get<double>(), 3.267e-3, 0.2 * 3.267e-3);
  // the step that named it said why it was tentative then
  std::string steps;
  for (const auto& st : g.findings["steps"]) steps += st["caveat"].get<std::string>() + "\n";
  EXPECT_NE(steps.find("its stiffness is not identified"), std::string::npos) << steps;
  EXPECT_LT(e[0]["gap_after"].get<double>(), 0.01 * e[0]["gap_before"].get<double>());
}

// The caveat of a tentative ripple is that of its final values (issue 20's review): fd-drivegen
// 11's ripple (pitch 71.62 mm over 137 mm, 2.05 periods in truth) was named with "69.27 +- 0.27
// mm (95 %) is within 1.1 % of the limit", where the final refits had it at 71.64 mm.
TEST(FitVerdict, ATentativeCaveatGivesTheFinalPitch) {
  using namespace issue20;
  const GeneratedFit g = generate_and_fit("tentative_final", "11 10 cogging_ripple,constant_force periods=2.05");
  ASSERT_TRUE(g.run.code == 0 || g.run.code == 3) << g.run.err << g.run.out;
  bool found = false;
  for (const auto& e : g.findings["effects"]) {
    if (e["name"] != "cogging_ripple" || !e["tentative"].get<bool>()) continue;
    found = true;
    char pitch[32];
    std::snprintf(pitch, sizeof pitch, "the fitted pitch %.4g +-", e["parameters"]["pitch"].get<double>() * 1e3);
    EXPECT_NE(e["caveat"].get<std::string>().find(pitch), std::string::npos) << e["caveat"] << " / " << pitch;
  }
  EXPECT_TRUE(found) << g.findings["conclusion"];
}

// The noise floor's terms (fit/verdict.hpp): the same record with its time stamps' error given
// (the generator's +-1 us, uniform: 0.577 us, DIR/knobs.txt) gets a higher floor -- v d_k per
// sample and the thrust's jumps switched early or late -- which findings.json carries with the
// force floor's parts; and the ripple's 23 um gap, ~400x the floor either way, stays unexplained.
TEST(FitVerdict, StampErrorRaisesTheFloorAndHidesNoEffect) {
  using namespace issue20;
  const GeneratedFit plain = generate_and_fit("verdict_stamps_plain", "5 10 cogging_ripple,mass_error periods=1.6");
  const fs::path dir = scratch() / "gen_verdict_stamps_plain";
  ASSERT_NE(slurp(dir / "knobs.txt").find("stamp_error_s 5.77350269"), std::string::npos);
  const fs::path out = scratch() / "verdict_stamps";
  const ProcResult r =
      run_fit("--scenario " + (dir / "model.yaml").string() + " --data " + (dir / "data.csv").string() + " --out " +
              out.string() + " --no-plots -q --time-stamp-error 5.7735e-7");
  ASSERT_EQ(r.code, 3) << r.err << r.out;
  ASSERT_EQ(plain.run.code, 3) << plain.run.err;
  const auto j = findings(out);
  const auto& f0 = plain.findings["noise_floor"];
  const auto& f1 = j["noise_floor"];
  EXPECT_DOUBLE_EQ(f1["stamp_error_s"].get<double>(), 5.7735e-7);
  EXPECT_EQ(f0["stamp_error_s"].get<double>(), 0.0);
  EXPECT_NE(f0["source"].get<std::string>().find("time-stamp error not given"), std::string::npos);
  // the stamps add to the floor, never take away (variances add)
  EXPECT_GT(f1["gap_m"].get<double>(), f0["gap_m"].get<double>());
  EXPECT_GT(f1["force_rms_N"].get<double>(), f0["force_rms_N"].get<double>());
  // the force floor = sensor/stamps and discretisation in quadrature; the discretisation does not
  // depend on the stamps' error
  EXPECT_GT(f1["force_discretisation_N"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(f1["force_discretisation_N"].get<double>(), f0["force_discretisation_N"].get<double>());
  EXPECT_NEAR(std::hypot(f1["force_noise_N"].get<double>(), f1["force_discretisation_N"].get<double>()),
              f1["force_rms_N"].get<double>(), 1e-9 * f1["force_rms_N"].get<double>());
  EXPECT_EQ(j["verdict"], "unexplained");
  EXPECT_GT(j["gap_final"].get<double>(), 100.0 * f1["gap_m"].get<double>());
  // The true error given is what the record shows: taken as given (above, stamp_error_s). One 35x
  // too large (20 us; issue 20's review: it raised the floor past a 1.5 % mass error and gave "no
  // discrepancy") would scatter the positions at speed 35x more than they are: it is taken at
  // the most the record allows (3x its scatter over the speed, verdict.cpp stamp_check): above
  // the true 0.58 us, and below 5x it (the 3x margin, up to 1.3x from the median of a uniform
  // rather than Gaussian scatter, and the sensor's share; 3.5x here), far below 20 us.
  const fs::path out_big = scratch() / "verdict_stamps_big";
  const ProcResult big =
      run_fit("--scenario " + (dir / "model.yaml").string() + " --data " + (dir / "data.csv").string() + " --out " +
              out_big.string() + " --no-plots -q --time-stamp-error 2e-5");
  ASSERT_EQ(big.code, 3) << big.err << big.out;
  const auto jb = findings(out_big);
  const auto& f2 = jb["noise_floor"];
  EXPECT_DOUBLE_EQ(f2["stamp_error_given_s"].get<double>(), 2e-5);
  EXPECT_GT(f2["stamp_error_s"].get<double>(), 5.7735e-7);
  EXPECT_LT(f2["stamp_error_s"].get<double>(), 5.0 * 5.7735e-7);
  EXPECT_NE(jb["conclusion"].get<std::string>().find("--time-stamp-error 20 us taken as"), std::string::npos);
}

// The settings cannot buy an all-clear (issue 20's review): a 0.5 N constant force hidden in the CI
// record's 4 s. A replay window of 10 ms and a filter half-width of 2 ms (each 10 and 2 sample
// periods, the shortest allowed) raise the smallest constant force the record shows from 0.02 N
// to 2 N: the force sits below both floors, and the tool said "no discrepancy". Now the fitted
// model is judged also at the defaults, which see the force: unexplained, exit 3, naming both
// settings. At the defaults the verdict is as before (the model form carries the 0.5 N as the
// friction's direction asymmetry, within 3 % of the friction level: no discrepancy).
TEST(FitVerdict, ShortWindowAndFilterGiveNoFalseAllClear) {
  using namespace issue20;
  const fs::path data = [] {
    const fs::path truth =
        write_file("truth_half_newton.yaml", short_scenario("  effects:\n    constant_force: {force: 0.5}\n"));
    const fs::path o = scratch() / "sim_half_newton";
    const ProcResult s = run(kSim, truth.string() + " --out " + o.string() + " --no-plots --quiet");
    if (s.code != 0) throw std::runtime_error("feeddrive-sim failed: " + s.err);
    return o / "timeseries.csv";
  }();
  const auto fit = [&](const std::string& name, const std::string& args) {
    const fs::path out = scratch() / name;
    const ProcResult r = run_fit("--scenario " + model4().string() + " --data " + data.string() + " --out " +
                                 out.string() + " --position-column x_measured --no-plots -q " + args);
    return std::make_pair(r, fs::exists(out / "findings.json") ? findings(out) : nlohmann::json());
  };
  // the defaults: unchanged, and the detection limit stated (the limit at the defaults is its own)
  const auto [d, jd] = fit("short_settings_default", "");
  ASSERT_EQ(d.code, 0) << d.err << d.out;
  // the 0.5 N is carried as the friction's direction asymmetry (model form): the model as given
  // was not within the floor (1.9 um of gap), so this is no "no discrepancy" but explained by the
  // model form, which the conclusion names (issue 20: no discrepancy = the initial residual at the floor)
  EXPECT_EQ(jd["verdict"], "explained") << jd["conclusion"];
  const std::string cd = jd["conclusion"];
  EXPECT_NE(cd.find("explained by the model form alone (no effect named)"), std::string::npos) << cd;
  EXPECT_NE(cd.find("friction direction asymmetry 0.49"), std::string::npos) << cd;
  EXPECT_NE(cd.find("the smallest constant force it shows: 0.0203 N at W = 0.1 s, L = 10 ms"), std::string::npos) << cd;
  const auto& fd = jd["noise_floor"];
  EXPECT_DOUBLE_EQ(fd["detection_limit_default_N"].get<double>(), fd["detection_limit_N"].get<double>());
  // the limit by the gap: gap_factor (3) gap floors times 2 m sqrt(180) / W^2 (verdict.hpp), m the
  // model's mass (with the motor's: effective_params); only rounding separates the two (1e-12);
  // by the force residual: force_factor (3) force floors
  const double m = feeddrive::plant::effective_params(feeddrive::sim::load_scenario(model4().string()).plant).mass;
  EXPECT_DOUBLE_EQ(fd["gap_factor"].get<double>(), 3.0);
  EXPECT_NEAR(fd["detection_limit_gap_N"].get<double>(),
              3.0 * fd["gap_m"].get<double>() * 2.0 * m * std::sqrt(180.0) / (0.1 * 0.1),
              1e-12 * fd["detection_limit_gap_N"].get<double>());
  EXPECT_DOUBLE_EQ(fd["detection_limit_force_N"].get<double>(),
                   fd["force_factor"].get<double>() * fd["force_rms_N"].get<double>());
  EXPECT_DOUBLE_EQ(fd["detection_limit_N"].get<double>(),
                   std::min(fd["detection_limit_gap_N"].get<double>(), fd["detection_limit_force_N"].get<double>()));
  EXPECT_LT(fd["detection_limit_N"].get<double>(), 0.5);  // the defaults see the force
  // The gap's formula on the force itself: without the model form the 0.5 N stays in the model's
  // residual, and the initial gap is the drift of 0.5 N W^2/(2m)/sqrt(180) = 1.83 um (measured
  // 1.91 um). 10 %: the sensor's 0.02 um adds in quadrature, and the model's friction answers the
  // drift's small change of speed (the formula is the free mass's).
  const auto [n, jn] = fit("short_settings_default_no_form", "--no-form-fit");
  ASSERT_EQ(n.code, 3) << n.err << n.out;
  const double drift = 0.5 * 0.1 * 0.1 / (2.0 * m) / std::sqrt(180.0);
  EXPECT_NEAR(jn["gap_initial"].get<double>(), drift, 0.1 * drift);
  // the constant force within the friction's asymmetry is what the rest resembles, and only holds
  // at rest separate the two (issue 20's review: it said "record reversals" on records with 17)
  std::string lines;
  for (const auto& u : jn["unexplained"]) lines += u.get<std::string>() + "\n";
  EXPECT_NE(lines.find("resembles constant_force"), std::string::npos) << lines;
  EXPECT_NE(lines.find("only the drive at rest tells them apart"), std::string::npos) << lines;
  // the shortest W and L, with and without the model form (without it the force is no asymmetry:
  // the defaults leave it in the residual, 1.9 um of gap)
  for (const std::string form : {"", "--no-form-fit"}) {
    SCOPED_TRACE(form);
    const auto [t, jt] = fit("short_settings" + form, "--replay-window 0.01 --filter-half-width 0.002 " + form);
    ASSERT_EQ(t.code, 3) << t.err << t.out;
    EXPECT_EQ(jt["verdict"], "unexplained");
    const std::string c = jt["conclusion"];
    EXPECT_NE(c.find("the chosen settings (--replay-window 0.01 s, --filter-half-width 2 ms) hide a discrepancy the "
                     "defaults (W = 0.1 s, L = 10 ms) see"),
              std::string::npos)
        << c;
    EXPECT_NE(c.find("the smallest constant force the record shows is 2.03 N with them (where the fitted model is "
                     "within their floor: gap "),
              std::string::npos)
        << c;
    EXPECT_NE(c.find("), 0.0203 N with the defaults, where the fitted model leaves a gap of "), std::string::npos) << c;
    EXPECT_EQ(c.find("within its noise"), std::string::npos) << c;
    const auto& ft = jt["noise_floor"];
    EXPECT_DOUBLE_EQ(ft["replay_window_s"].get<double>(), 0.01);
    EXPECT_DOUBLE_EQ(ft["filter_half_width_s"].get<double>(), 0.002);
    // W 10x shorter: the gap's limit 100x higher (the gap floor is sigma_x at any W without stamp
    // errors); the default limit is the default run's
    EXPECT_NEAR(ft["detection_limit_gap_N"].get<double>() / fd["detection_limit_gap_N"].get<double>(), 100.0, 1e-9);
    EXPECT_DOUBLE_EQ(ft["detection_limit_default_N"].get<double>(), fd["detection_limit_N"].get<double>());
    EXPECT_GT(ft["detection_limit_N"].get<double>(), 0.5);  // these settings cannot show the force
    EXPECT_NE(slurp(scratch() / ("short_settings" + form) / "report.md")
                  .find("Detection limit: the smallest constant force this record shows at W = 0.01 s, L = 2 ms is "
                        "2.03 N"),
              std::string::npos);
  }
}

// The issue's first case: a 40.2 mm ripple over 78.7 mm (pitch 2.2 % above travel/2) and a
// 10.7 N constant force. The ripple is named as tentative with its caveat; a spring named first
// for the ripple's remnant turns into a constant force once the ripple is in (swap move), and the
// gap reaches the floor. Every parameter has its 95 % interval.
TEST(FitVerdict, BorderlinePitchIsTentativeAndASpringWithoutSlopeIsSwapped) {
  using namespace issue20;
  const GeneratedFit g = generate_and_fit("verdict_tentative", "5 10 cogging_ripple,constant_force periods=1.97");
  const ProcResult& r = g.run;
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  const auto& j = g.findings;
  std::map<std::string, nlohmann::json> named;
  for (const auto& e : j["effects"]) named[e["name"].get<std::string>()] = e;
  ASSERT_TRUE(named.count("cogging_ripple")) << j["conclusion"];
  ASSERT_TRUE(named.count("constant_force")) << j["conclusion"];
  EXPECT_FALSE(named.count("spring_force")) << j["conclusion"];
  EXPECT_TRUE(named["cogging_ripple"]["tentative"].get<bool>());
  EXPECT_NE(named["cogging_ripple"]["caveat"].get<std::string>().find("record a travel of at least 3 periods"),
            std::string::npos);
  // the truth (fd-drivegen's truth.txt): pitch 40.19 mm, 10.70 N; 2 % and 20 % as the sweep
  EXPECT_NEAR(named["cogging_ripple"]["parameters"]["pitch"].get<double>(), 0.0401917, 0.02 * 0.0401917);
  EXPECT_NEAR(named["constant_force"]["parameters"]["force"].get<double>(), 10.6976, 0.2 * 10.6976);
  for (const auto& [n, e] : named)
    for (const auto& [k, v] : e["parameters"].items()) EXPECT_TRUE(e["ci95"].contains(k)) << n << "." << k;
  bool swapped = false;
  for (const auto& st : j["steps"]) swapped = swapped || st["swap"] == "spring_force -> constant_force";
  EXPECT_TRUE(swapped) << j["steps"].dump().substr(0, 2000);
  EXPECT_EQ(j["verdict"], "explained") << j["conclusion"];
}

// A ripple over 1.75 periods (bench/fit_bench.sh's record 40000153 of issue 20's mix: an 8.9 N
// cogging ripple of 62.6 mm pitch over 110 mm of travel): the ripple cannot be named (fewer than
// two periods), and a spring, whose slope matches the sinusoid over part of the travel, scored 51
// against the ripple's ~3000 and was named before. Now the spring is passed over as the ripple's
// stand-in, and the verdict is unexplained with what would settle it.
// The swap on the final model (issue 20's review): on a one-direction record of a hidden constant
// force, the spring named at step 1 collapses under the model form's refit into a force without
// slope (its rest position metres outside the travel, implausible); it is swapped for the
// constant force it has become, and the spring is not named.
TEST(FitVerdict, ASpringCollapsedByTheLastRefitsIsSwappedForItsConstantForce) {
  const GeneratedFit g = generate_and_fit("swap_final", "1554002451 10 constant_force onedir");
  ASSERT_TRUE(g.run.code == 0 || g.run.code == 3) << g.run.err;
  std::vector<std::string> named;
  for (const auto& e : g.findings["effects"]) named.push_back(e["name"]);
  EXPECT_EQ(named, std::vector<std::string>{"constant_force"}) << g.findings["conclusion"];
}

TEST(FitVerdict, ASpringIsNotNamedForARippleSeenOverFewerThanTwoPeriods) {
  using namespace issue20;
  const GeneratedFit g =
      generate_and_fit("verdict_short_ripple", "40000153 10 cogging_ripple periods=1.7547241924127941");
  const ProcResult& r = g.run;
  ASSERT_EQ(r.code, 3) << r.err << r.out;
  const auto& j = g.findings;
  for (const auto& e : j["effects"]) EXPECT_NE(e["name"], "spring_force") << j["conclusion"];
  bool stand_in = false;
  for (const auto& st : j["steps"])
    for (const auto& c : st["ranking"])
      stand_in = stand_in || (c["name"] == "spring_force" &&
                              c["passed_over"].get<std::string>().find("stands in for a force periodic in position") !=
                                  std::string::npos);
  EXPECT_TRUE(stand_in) << j["steps"].dump().substr(0, 3000);
  std::string all;
  for (const auto& u : j["unexplained"]) all += u.get<std::string>() + "\n";
  EXPECT_NE(all.find("a force periodic in position, pitch about"), std::string::npos) << all;
  EXPECT_NE(all.find("record a travel of at least 3 periods"), std::string::npos) << all;
}

// Ties: moves in one direction only (fd-drivegen onedir) with a hidden Coulomb friction. A
// Coulomb friction and a constant force are the same force while the drive moves one way: the
// report names both and says a reversal would separate them.
TEST(FitVerdict, OneDirectionCoulombAndConstantForceAreReportedAsATie) {
  using namespace issue20;
  const GeneratedFit g = generate_and_fit("verdict_tie", "2 10 coulomb_friction onedir");
  const ProcResult& r = g.run;
  ASSERT_TRUE(r.code == 0 || r.code == 3) << r.err << r.out;
  const auto& j = g.findings;
  ASSERT_EQ(j["ties"].size(), 1u) << j.dump().substr(0, 3000);
  const std::string tie = j["ties"][0];
  EXPECT_NE(tie.find("coulomb_friction"), std::string::npos) << tie;
  EXPECT_NE(tie.find("constant_force"), std::string::npos) << tie;
  EXPECT_NE(tie.find("the record cannot separate them"), std::string::npos) << tie;
  EXPECT_NE(tie.find("reversal"), std::string::npos) << tie;
  EXPECT_NE(r.out.find("tie: "), std::string::npos) << r.out;
}

// A logger's file: time in ms, position in mm, semicolons and decimal commas, read with
// --separator, --decimal-comma, --units and the logger's column names; then the same with the
// columns by index, and an encoder in counts with the force in kN. Each finds the 15 N force.
TEST(FitData, LoggerFilesWithTheirOwnSeparatorDecimalCommaUnitsAndColumns) {
  using namespace issue20;
  const auto comma = [](std::string s) {
    std::replace(s.begin(), s.end(), '.', ',');
    return s;
  };
  const fs::path logger =
      write_file("logger.csv", derived(
                                   {"time_ms", "pos_mm", "force_N"},
                                   [&](const auto& c, std::size_t k) {
                                     return std::vector<std::string>{comma(g17(num(c.at("t")[k]) * 1e3)),
                                                                     comma(g17(num(c.at("x_measured")[k]) * 1e3)),
                                                                     comma(c.at("f_thrust")[k])};
                                   },
                                   ";"));
  // without the options: refused, and the line says which option reads it
  expect_data_error("logger_plain.csv", slurp(logger), {"separated by commas", "--separator"});
  const auto fit_ok = [&](const std::string& name, const fs::path& data, const std::string& args) {
    SCOPED_TRACE(name);
    const fs::path out = scratch() / name;
    const ProcResult r = run_fit("--scenario " + model4().string() + " --data " + data.string() + " --out " +
                                 out.string() + " --no-plots -q --max-effects 1 " + args);
    ASSERT_TRUE(r.code == 0 || r.code == 3) << r.err << r.out;
    const auto j = findings(out);
    ASSERT_FALSE(j["effects"].empty()) << j["conclusion"];
    EXPECT_EQ(j["effects"][0]["name"], "constant_force");
    // 20 % as FindsAConstantForceEndToEnd: the same record in other units
    EXPECT_NEAR(j["effects"][0]["parameters"]["force"].get<double>(), 15.0, 3.0);
  };
  fit_ok("logger_out", logger,
         "--separator ';' --decimal-comma --units t=ms,x=mm --time-column time_ms --position-column pos_mm "
         "--force-column force_N");
  fit_ok("logger_index_out", logger,
         "--separator ';' --decimal-comma --units t=ms,x=mm --time-column 1 --position-column 2 --force-column 3");
  // a 50 nm encoder in counts (the simulated encoder's quantum), time in us, force in kN, tabs
  const fs::path counts =
      write_file("counts.tsv", derived(
                                   {"t_us", "enc", "F_kN"},
                                   [&](const auto& c, std::size_t k) {
                                     return std::vector<std::string>{g17(num(c.at("t")[k]) * 1e6),
                                                                     g17(std::round(num(c.at("x_measured")[k]) / 5e-8)),
                                                                     g17(num(c.at("f_thrust")[k]) * 1e-3)};
                                   },
                                   "\t"));
  fit_ok("counts_out", counts,
         "--separator tab --units t=us,x=counts:5e-8,force=kN --time-column t_us --position-column enc --force-column "
         "F_kN");
  // a bad unit and a decimal comma with comma separators: one line, exit 2
  expect_data_error("units_bad.csv", slurp(simulated_data()), {"--units 'x=inch'", "unknown unit 'inch' for x"},
                    "--units x=inch --position-column x_measured");
  const ProcResult dc = run_fit("--scenario x.yaml --data y.csv --out z --decimal-comma");
  EXPECT_EQ(dc.code, 2);
  EXPECT_NE(dc.err.find("--decimal-comma needs another --separator"), std::string::npos) << dc.err;
}

// Sanity before fitting: a CSV made from the CI record by scaling one column, or by joining two
// recordings, is refused with one line naming the column and the likely unit, or the row and
// the size of the jump (exit 2, nothing written).
TEST(FitData, ScaleOffByAThousandAndJumpsAreRefusedBeforeFitting) {
  using namespace issue20;
  const auto make = [&](double t_scale, double x_scale, double f_scale, double t_jump, double x_jump) {
    return edited([=](std::size_t k, double& t, double& x, double& f) {
      const bool after = k >= 2000;  // the second recording starts at row 2000 (file line 2002)
      t = t * t_scale + (after ? t_jump : 0.0);
      x = x * x_scale + (after ? x_jump : 0.0);
      f *= f_scale;
      return true;
    });
  };
  expect_data_error("pos_mm.csv", make(1, 1e3, 1, 0, 0),
                    {"column 'x'", "beyond a feed drive", "likely in mm (--units x=mm)"});
  // Units that are no power of 1000 of a metre are named by the thrust balance's factor, not
  // snapped to one (issue 20's review: cm, inches and 0.1 mm were all "likely in mm"); the
  // balance has the record's own friction and the model's mass, 2.6 % off here (0.00974 m for cm).
  expect_data_error("pos_cm.csv", make(1, 1e2, 1, 0, 0),
                    {"column 'x'", "beyond a feed drive", "likely in cm (--units x=counts:0.01)"});
  expect_data_error("pos_in.csv", make(1, 1.0 / 0.0254, 1, 0, 0),
                    {"column 'x'", "beyond a feed drive", "likely in inches (--units x=counts:0.0254)"});
  // a thrust 40x off (beyond the 30x a mass error may give, and no power of 1000): its factor,
  // both ways (the force's unit, or the position's), where a power of 1000 was named before; the
  // balance measures 38.9 (the record's friction and the model's mass: 2.8 % off, as for cm)
  expect_data_error("force_40.csv", make(1, 1, 40.0, 0, 0),
                    {"columns 'force_N' and 'x'", "no power of 1000", "--units force=counts:0.026"});
  // time in 100 us ticks: 10 ticks per 1 ms control period, no power of 1000 (was "likely in ms")
  expect_data_error("t_ticks.csv", make(1e4, 1, 1, 0, 0),
                    {"column 't'", "no power of 1000", "makes its unit 0.0001 s (--units t=counts:0.0001)"});
  // and a thrust 1/40 (a position in inches, read as m, that stays below 10 m/s): both ways
  expect_data_error("force_1_40.csv", make(1, 1, 1.0 / 40.0, 0, 0),
                    {"no power of 1000", "--units force=counts:41", "or the position's 0.0243 m"});
  // Encoder counts (whole numbers) are named as counts with the scenario's encoder step, not as a
  // power of 1000 of a metre (issue 20's review: "likely in um" was 9.4x off).
  expect_data_error("pos_counts.csv", edited([](std::size_t, double&, double& x, double&) {
                      x = std::round(x / 5e-8);
                      return true;
                    }),
                    {"column 'x'", "whole numbers: likely encoder counts (--units x=counts:5e-08"});
  expect_data_error("time_ms.csv", make(1e3, 1, 1, 0, 0),
                    {"column 't'", "control period", "likely in ms (--units t=ms)"});
  expect_data_error("force_kN.csv", make(1, 1, 1e-3, 0, 0), {"column 'force_N'", "likely in kN (--units force=kN)"});
  // Every column both ways, each named alone (issue 20's review: a time divided by 1000 was named
  // as column 'x', a position divided by 1000 as the force). A time 1000x too short: the time is
  // named (its period against the control period, confirmed by a speed no drive reaches), in ks,
  // which --units gives as counts.
  expect_data_error("time_ks.csv", make(1e-3, 1, 1, 0, 0),
                    {"time_ks.csv: column 't': median sample period 1e-06 s", "speeds up to",
                     "likely in ks (--units t=counts:1000: 1000 s per unit)"});
  // a position 1000x too small: its steps are 1/1000 of the scenario's 50 nm encoder step
  expect_data_error("pos_km.csv", make(1, 1e-3, 1, 0, 0),
                    {"pos_km.csv: column 'x': its smallest step 5e-11 m is 0.001 times the scenario's encoder step",
                     "likely in km (--units x=counts:1000: 1000 m per unit)"});
  // a force 1000x too large: the position's steps are the encoder's, so the force alone is named
  expect_data_error("force_mN.csv", make(1, 1, 1e3, 0, 0),
                    {"force_mN.csv: column 'force_N': the thrust is", "likely in mN (--units force=mN)"});
  // the same, against units declared wrongly: the likely unit is the one the file is in
  expect_data_error("time_s_as_ms.csv", make(1, 1, 1, 0, 0),
                    {"time_s_as_ms.csv: column 't'", "likely in s (--units t=s)"}, "--units t=ms");
  expect_data_error("pos_m_as_um.csv", make(1, 1, 1, 0, 0),
                    {"pos_m_as_um.csv: column 'x'", "likely in m (--units x=m)"}, "--units x=um");
  expect_data_error("force_N_as_kN.csv", make(1, 1, 1, 0, 0),
                    {"force_N_as_kN.csv: column 'force_N'", "likely in N (--units force=N)"}, "--units force=kN");
  expect_data_error("joined.csv", make(1, 1, 1, 1000, 0),
                    {"joined.csv:2002: column 't': the time jumps by 1000 s", "two recordings joined"});
  expect_data_error("joined_offset.csv", make(1, 1, 1, 1000, 0.05),
                    {"joined_offset.csv:2002:", "the time jumps by 1000 s"});
  // A jump of 50 um, 250x the record's 0.2 um of motion noise (issue 20's review: it passed
  // under the 20x-peak-thrust limit).
  expect_data_error("pos_jump_50um.csv", make(1, 1, 1, 0, 50e-6),
                    {"pos_jump_50um.csv:2002: column 'x': the position jumps by 0.050", "mm in one sample"});
  expect_data_error("pos_jump.csv", make(1, 1, 1, 0, 0.05),
                    {"pos_jump.csv:2002: column 'x': the position jumps by 50 mm in one sample", "split the file"});
  // Issue 20's review: a reversed sign (the thrust is -1 times m a), a force channel switched off,
  // and a record sampled every other control period (the thrust not held over a sample) were fitted.
  expect_data_error("pos_reversed.csv", make(1, -1, 1, 0, 0),
                    {"columns 'force_N' and 'x': the thrust is -", "sign of one of them is reversed"});
  expect_data_error("force_reversed.csv", make(1, 1, -1, 0, 0), {"sign of one of them is reversed"});
  expect_data_error("force_zero.csv", make(1, 1, 0, 0, 0),
                    {"column 'force_N': constant (0) over the whole record while the drive moves"});
  expect_data_error("every_other.csv", edited([](std::size_t k, double&, double&, double&) {
                      return k % 2 == 0;  // every other row: 500 Hz of 1 kHz
                    }),
                    {"column 't': median sample period 0.002 s is 2 times the scenario's control period 0.001 s"});
}

// A step of the position of a few um, one sample off, and a gap in time with an offset (issue 20's
// review of the sanity checks): a 5 or 10 um step passed (its acceleration stays within what the
// peak thrust gives) and was fitted as a force; a 10 um spike was named one row late as "two
// recordings joined"; a 9-period gap with a 1 mm offset named only the position. Each is now
// named at its own row with its size: the step by its doublet in the second difference (+J then
// -J, fit/sanity.cpp find_step), the spike as an outlier, the gap with both columns.
// A time gap shorter than the refusal's 10 periods passes, and the report says so (issue 20's
// review: 20 % of the rows dropped, and a 9-period gap, passed without a word): the CI record
// with rows 2000-2005 dropped (a gap of 7 periods) and every 10th row of 1000-1199 (20 gaps of 2).
TEST(FitData, ShortTimeGapsPassWithANote) {
  using namespace issue20;
  const fs::path data = write_file("gaps.csv", edited([](std::size_t k, double&, double&, double&) {
                                     return !(k >= 2000 && k <= 2005) && !(k >= 1000 && k < 1200 && k % 10 == 5);
                                   }));
  const fs::path out = scratch() / "gaps";
  const ProcResult r = run_fit("--scenario " + model4().string() + " --data " + data.string() + " --out " +
                               out.string() + " --no-plots -q");
  ASSERT_TRUE(r.code == 0 || r.code == 3) << r.err << r.out;
  const auto j = findings(out);
  std::string notes;
  for (const auto& n : j["data"]["notes"]) notes += n.get<std::string>() + "\n";
  EXPECT_NE(notes.find("time gaps: 21 intervals longer than 1.5 sample periods"), std::string::npos) << notes;
  EXPECT_NE(notes.find("about 26 samples"), std::string::npos) << notes;
  EXPECT_NE(notes.find("the largest 7 periods at"), std::string::npos) << notes;
}

TEST(FitData, SmallStepsSpikesAndGapsAreNamedAtTheirRow) {
  using namespace issue20;
  const auto step = [](double J) {
    return edited([=](std::size_t k, double&, double& x, double&) {
      x += k >= 2000 ? J : 0.0;  // from row 2000 (file line 2002) on
      return true;
    });
  };
  // The size in the line, against the size made: within 0.2 um, four of the record's 50 nm encoder
  // steps (the step less the motion around it, from the velocities on either side, and the spike
  // against the cubic through its neighbours, each a few quantized samples).
  const auto size_mm = [](const std::string& line, const std::string& before) {
    const auto at = line.find(before);
    return at == std::string::npos ? NAN : std::stod(line.substr(at + before.size()));
  };
  for (const double J : {5e-6, -10e-6}) {
    const std::string line = expect_data_error("step.csv", step(J),
                                               {"step.csv:2002: column 'x': the position jumps by ", "mm in one sample",
                                                "a step no thrust gives", "split the file"});
    EXPECT_NEAR(size_mm(line, "the position jumps by "), J * 1e3, 0.2e-3) << line;
  }
  const std::string spike = edited([](std::size_t k, double&, double& x, double&) {
    x += k == 2000 ? 10e-6 : 0.0;  // row 2000 only, file line 2002
    return true;
  });
  const std::string spiked = expect_data_error(
      "spike.csv", spike, {"spike.csv:2002: column 'x': position", "is an outlier, ", "mm off the course"});
  EXPECT_NEAR(size_mm(spiked, "is an outlier, "), 10e-3, 0.2e-3) << spiked;
  EXPECT_EQ(spiked.find("joined"), std::string::npos) << spiked;
  // rows 1992-1999 left out (a 9-period step of the time) and 1 mm added from row 2000 (file line 1994)
  const std::string gap = edited([](std::size_t k, double&, double& x, double&) {
    x += k >= 2000 ? 1e-3 : 0.0;
    return k < 1992 || k >= 2000;
  });
  const std::string gapped = expect_data_error(
      "gap_offset.csv", gap,
      {"gap_offset.csv:1994: columns 't' and 'x': the time jumps by 0.009 s (9 sample periods of 0.001 s) and the "
       "position by "});
  // within 1 um: the motion over the 9 ms the gap hides is taken from the velocities on either side
  // (exact for a constant acceleration; the thrust changes within 9 ms: here 0.4 um)
  EXPECT_NEAR(size_mm(gapped, "and the position by "), 1.0, 1e-3) << gapped;
}

namespace feeddrive::fit {
namespace {

// model.fitted.yaml is written into the output folder: every file name of the scenario
// (sim::file_keys: a waypoints table, an open-loop table, a plugin) must still name its file from
// there (the review of issue 22 found controller.file left relative: the fitted model did not load).
TEST(FitReport, FittedScenarioNamesItsFilesFromAnyFolder) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("fd_fitted_files_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "in");
  fs::create_directories(dir / "out");
  std::ofstream(dir / "in" / "u.csv") << "t,u\n0,0\n1,0.1\n";
  std::ofstream(dir / "in" / "w.csv") << "t,x\n0,0\n1,0.001\n";
  std::ofstream(dir / "in" / "s.yaml")
      << "duration: 0.01\ncontrol_period: 1e-3\ncontroller: {type: open_loop, kind: csv, file: u.csv}\n"
         "reference: {type: waypoints, file: w.csv}\n";
  plant::PlantParams fitted;
  fitted.effects.constant_force.enabled = true;
  fitted.effects.constant_force.force = 3.0;
  const std::string yaml = fitted_scenario_yaml((dir / "in" / "s.yaml").string(), fitted);
  const sim::Scenario s = sim::parse_scenario(yaml, (dir / "out").string(), "model.fitted.yaml");
  EXPECT_EQ(fs::path(s.controller.open_loop_file), (dir / "in" / "u.csv").lexically_normal());
  EXPECT_EQ(fs::path(s.reference.waypoints_file), (dir / "in" / "w.csv").lexically_normal());
  EXPECT_DOUBLE_EQ(s.plant.effects.constant_force.force, 3.0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace feeddrive::fit
