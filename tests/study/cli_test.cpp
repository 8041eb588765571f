// feeddrive-study end to end: parallel runs give the same bytes, reruns skip finished cases (and
// only those whose scenario is unchanged), failed cases are reported while the others go on, bad
// studies exit 2 with one line, and the output folder follows feeddrive::output's rules.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "../support/scratch.hpp"
#include "study_util.hpp"

namespace {
namespace fs = std::filesystem;
using feeddrive::test_support::slurp;

const std::string kStudy = std::string(FEEDDRIVE_BINARY_DIR) + "/bin/feeddrive-study";

fs::path scratch() {
  static const fs::path dir = feeddrive::test_support::make_scratch("study-cli");
  return dir;
}

fs::path write_file(const std::string& name, const std::string& text) {
  return feeddrive::test_support::write_text(scratch() / name, text);
}

struct ProcResult {
  int code;
  std::string err;
};

ProcResult study(const std::string& args) {
  const fs::path err = scratch() / "stderr.txt";
  const int status = std::system((kStudy + " " + args + " 2> " + err.string() + " > /dev/null").c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(err)};
}

// 2 controllers x (1 + 2 + 3 draws) cases of 20 ms; one family fails by design (a CVODE step
// budget of one step).
std::string small_study(const std::string& extra_value = "0.8") {
  return feeddrive::study::test::study_text(
      "controllers:\n"
      "  - {name: smc, scenario: " +
      feeddrive::study::test::scenarios() +
      "/smc_bl_jerk_limited.yaml}\n"
      "  - {name: cascade, controller: {type: cascade, kv: 3000}}\n"
      "families:\n"
      "  - name: nominal\n"
      "  - name: mass\n"
      "    grid: [{key: plant.mass, scale: [" +
      extra_value +
      ", 1.2]}]\n"
      "  - name: mc\n"
      "    monte_carlo:\n"
      "      draws: 3\n"
      "      seed: 5\n"
      "      parameters:\n"
      "        - {keys: [plant.friction.static_force, plant.friction.coulomb_force], distribution: uniform, low: 0.7, "
      "high: 1.3, scale: true}\n"
      "  - name: broken\n"
      "    set: {plant.integrator.max_steps: 1}\n"
      "report: {limit: 0.8}\n");
}

nlohmann::json timing(const fs::path& dir) { return nlohmann::json::parse(slurp(dir / "timing.json")); }

TEST(StudyCli, SameBytesForAnyJobsAndRerunsSkipFinishedCases) {
  const fs::path s = write_file("small.yaml", small_study());
  const fs::path a = scratch() / "a", b = scratch() / "b";
  ProcResult r = study(s.string() + " --out " + a.string() + " -j 1 --no-plots");
  ASSERT_EQ(r.code, 0) << r.err;
  r = study(s.string() + " --out " + b.string() + " -j 3");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string csv = slurp(a / "results.csv");
  EXPECT_EQ(csv, slurp(b / "results.csv"));
  // 1 header + 2 x 7 cases; the two broken ones failed with CVODE's error, the others went on.
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 15);
  EXPECT_EQ(timing(a)["cases_run"], 14);
  std::istringstream lines(csv);
  std::string line;
  int failed = 0;
  while (std::getline(lines, line))
    if (line.find(",broken,") != std::string::npos) {
      // The error names the keys with commas in it, so the CSV field is quoted.
      EXPECT_NE(line.find(",false,\"CVODE: CVode failed"), std::string::npos) << line;
      ++failed;
    }
  EXPECT_EQ(failed, 2);
  EXPECT_TRUE(fs::exists(b / "report.md"));
  EXPECT_TRUE(fs::exists(b / "plots" / "box.png"));
  EXPECT_NE(slurp(b / "report.md").find("| smc | 7 | 1 |"), std::string::npos);

  // A rerun runs nothing and writes the same bytes.
  r = study(s.string() + " --out " + a.string() + " --no-plots");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(timing(a)["cases_run"], 0);
  EXPECT_EQ(slurp(a / "results.csv"), csv);
  // --retry-failed runs the two failed ones again.
  r = study(s.string() + " --out " + a.string() + " --no-plots --retry-failed");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(timing(a)["cases_run"], 2);
  // A changed study reruns exactly the cases whose scenario changed (mass x0.9 instead of x0.8,
  // one case per controller), never a stale one.
  const fs::path s2 = write_file("small2.yaml", small_study("0.9"));
  r = study(s2.string() + " --out " + a.string() + " --no-plots");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(timing(a)["cases_run"], 2);
  const std::string csv2 = slurp(a / "results.csv");
  EXPECT_NE(csv2, csv);
  EXPECT_NE(csv2.find(",91.836"), std::string::npos);  // 102.04 x 0.9
  EXPECT_EQ(csv2.find(",81.632"), std::string::npos);  // 102.04 x 0.8 is gone
}

// Issue 19, point 9: the cases are resolved as they are handed out; before any runs, only the
// probe cases (each grid value once, cases.hpp). A case that fails to resolve later (here only
// the combination static 50 N < Coulomb 80 N is invalid; each value alone is fine) is a failed
// case in results.csv, named by the loader's one line, and the others run.
TEST(StudyCli, ACaseThatDoesNotResolveIsAFailedCase) {
  const fs::path s = write_file("combo.yaml", feeddrive::study::test::study_text(
                                                  "families:\n  - name: f\n    grid:\n"
                                                  "      - {key: plant.friction.static_force, values: [100, 50]}\n"
                                                  "      - {key: plant.friction.coulomb_force, values: [40, 80]}\n"));
  const fs::path out = scratch() / "combo";
  const ProcResult r = study(s.string() + " --out " + out.string() + " --no-plots -q");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string csv = slurp(out / "results.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5) << csv;
  EXPECT_NE(csv.find("\n3,base,f,3,,,50,80,false,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("plant.friction.static_force = 50: must be >= coulomb_force"), std::string::npos) << csv;
  EXPECT_EQ(timing(out)["cases_run"], 3);
  EXPECT_EQ(timing(out)["cases_not_resolved"], 1);
  EXPECT_NE(slurp(out / "report.md").find("| 3 | base | f |"), std::string::npos);
}

TEST(StudyCli, BadStudiesAndFoldersExit2WithOneLine) {
  const auto one_line = [](const ProcResult& r) {
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    return r.err;
  };
  const fs::path bad =
      write_file("bad.yaml", feeddrive::study::test::study_text(
                                 "families:\n  - {name: f, grid: [{key: plant.frction.static_force, values: [1]}]}\n"));
  EXPECT_NE(one_line(study(bad.string() + " --out " + (scratch() / "x").string())).find("plant.frction: unknown key"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(scratch() / "x"));  // nothing written for a bad study
  const fs::path mc = write_file(
      "mc.yaml", feeddrive::study::test::study_text("families:\n  - name: f\n    monte_carlo: {draws: 2, seed: 1, "
                                                    "parameters: [{key: plant.mass, distribution: weibull}]}\n"));
  EXPECT_NE(one_line(study(mc.string() + " --out " + (scratch() / "x").string()))
                .find("distribution = 'weibull': expected one of uniform, normal, lognormal"),
            std::string::npos);
  // A key of two axes of one family (review of issue 22): once exit 0 and duplicate cases.
  const fs::path twice = write_file(
      "twice.yaml", feeddrive::study::test::study_text("families:\n  - {name: f, grid: [{key: plant.mass, values: "
                                                       "[100, 120]}, {key: plant.mass, values: [3]}]}\n"));
  EXPECT_NE(one_line(study(twice.string() + " --out " + (scratch() / "x").string()))
                .find("families[0]: grid[0] plant.mass and grid[1] plant.mass: one key varied twice in family 'f'"),
            std::string::npos);
  EXPECT_NE(one_line(study((scratch() / "missing.yaml").string() + " --out " + (scratch() / "x").string()))
                .find("cannot read the study file"),
            std::string::npos);
  // A folder feeddrive did not write is never touched.
  const fs::path mine = scratch() / "mine";
  fs::create_directories(mine);
  std::ofstream(mine / "notes.txt") << "keep";
  const fs::path ok = write_file("ok.yaml", feeddrive::study::test::study_text(""));
  EXPECT_NE(one_line(study(ok.string() + " --out " + mine.string())).find("is not a feeddrive output"),
            std::string::npos);
  EXPECT_EQ(slurp(mine / "notes.txt"), "keep");
  // -j must be a count.
  EXPECT_EQ(study(ok.string() + " --out " + (scratch() / "y").string() + " -j 0").code, 2);
}

TEST(StudyCli, ReplacesTheOutputOfAnotherFeeddriveTool) {
  const fs::path dir = scratch() / "was_sim";
  const std::string sim = std::string(FEEDDRIVE_BINARY_DIR) + "/bin/feeddrive-sim";
  ASSERT_EQ(std::system((sim + " " + feeddrive::study::test::scenarios() + "/smc_bl_jerk_limited.yaml --out " +
                         dir.string() + " --no-plots --quiet")
                            .c_str()),
            0);
  ASSERT_TRUE(fs::exists(dir / "timeseries.csv"));
  const fs::path ok = write_file("ok2.yaml", feeddrive::study::test::study_text(""));
  const ProcResult r = study(ok.string() + " --out " + dir.string() + " --no-plots");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir / "timeseries.csv"));
  EXPECT_TRUE(fs::exists(dir / "results.csv"));
  EXPECT_NE(slurp(dir / ".feeddrive-output").find("tool: feeddrive-study"), std::string::npos);
}

TEST(StudyCli, WithoutGnuplotTheResultsAndReportAreStillWritten) {
  // Plots are a view: a missing gnuplot once cost the report (exit 1, a stray .plots.partial).
  const fs::path dir = scratch() / "no_gnuplot";
  const fs::path f = write_file("nogp.yaml", feeddrive::study::test::study_text(""));
  const int status = std::system(("PATH=/nonexistent " + kStudy + " -q " + f.string() + " --out " + dir.string() +
                                  " -j 1 2> " + (scratch() / "nogp.err").string() + " > /dev/null")
                                     .c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << slurp(scratch() / "nogp.err");
  EXPECT_NE(slurp(scratch() / "nogp.err").find("plots not drawn ("), std::string::npos)
      << slurp(scratch() / "nogp.err");
  EXPECT_TRUE(fs::exists(dir / "results.csv"));
  EXPECT_NE(slurp(dir / "report.md").find("Plots not drawn"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / ".plots.partial"));
}

TEST(StudyCli, ACaseWithoutAValueOfTheMetricIsNotCountedAsFailed) {
  // A settled metric of a run shorter than settled_after (0.02 s < 0.25 s) has no value: the
  // report once counted such cases as failed while results.csv said ok.
  const fs::path dir = scratch() / "no_value";
  const fs::path f = write_file(
      "novalue.yaml", feeddrive::study::test::study_text("report: {metric: position_error_max_abs_settled_m}\n"));
  const ProcResult r = study("-q --no-plots " + f.string() + " --out " + dir.string() + " -j 1");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string md = slurp(dir / "report.md");
  EXPECT_EQ(md.find("failed)"), std::string::npos) << md;
  EXPECT_NE(md.find("(1 without a value)"), std::string::npos) << md;
}

}  // namespace

namespace {
// Issue 23: a sweep without a study file, and --set on every case; the report has a table of the
// metric against each value, in the key's engineering unit, and names the model rule.
TEST(StudyCli, SweepWithoutAStudyFileReportsTheMetricAgainstEachValue) {
  const std::string scen = feeddrive::study::test::scenarios() + "/smc_bl_jerk_limited.yaml";
  const fs::path out = scratch() / "sweep";
  const ProcResult r =
      study(scen + " --sweep plant.mass=80:120:3 --set duration=0.02 --out " + out.string() + " -j 2 --no-plots");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string csv = slurp(out / "results.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4);  // header + 3 cases
  const std::string md = slurp(out / "report.md");
  EXPECT_NE(md.find("| plant.mass [kg] |"), std::string::npos) << md;
  for (const char* v : {"| 80 |", "| 100 |", "| 120 |"}) EXPECT_NE(md.find(v), std::string::npos) << v << "\n" << md;
  EXPECT_NE(md.find("nominal model"), std::string::npos);
  // A length in its engineering unit: 1e-9 .. 1e-7 m shown in um.
  const fs::path q = scratch() / "sweep_q";
  const ProcResult rq = study(scen + " --sweep plant.sensor.quantization=log:1e-9:1e-7:3 --set duration=0.02 --out " +
                              q.string() + " -j 2 --no-plots");
  ASSERT_EQ(rq.code, 0) << rq.err;
  const std::string mq = slurp(q / "report.md");
  EXPECT_NE(mq.find("| plant.sensor.quantization [um] |"), std::string::npos) << mq;
  EXPECT_NE(mq.find("| 0.01 |"), std::string::npos) << mq;  // 1e-8 m
  // Bad sweeps and settings: exit 2, one line.
  for (const auto& [args, expected] : std::vector<std::pair<std::string, std::string>>{
           {"--sweep plant.mass=1:2", "--sweep plant.mass=1:2: a range is START:STOP:N"},
           {"--sweep plant.mass=log:-1:2:3", "START and STOP > 0"},
           {"--sweep plant.mas=1,2", "plant.mas: unknown key (did you mean 'mass'?)"},
           {"--sweep plant.mass=1,2 --set plant.mass", "--set plant.mass: expected key=value"}}) {
    const ProcResult b = study(scen + " " + args + " --out " + (scratch() / "bad_sweep").string());
    EXPECT_EQ(b.code, 2) << args << ": " << b.err;
    EXPECT_NE(b.err.find(expected), std::string::npos) << b.err;
    EXPECT_EQ(std::count(b.err.begin(), b.err.end(), '\n'), 1) << b.err;
  }
}

}  // namespace

namespace {
// Review of issue 23 (F3): the loader's warnings of a sweep's cases reach the user, once per
// distinct warning with its count, on stderr and in report.md; results.csv has move_finished.
TEST(StudyCli, ASweepShowsItsCasesWarningsAndTheMovesThatDidNotFinish) {
  const std::string scen = feeddrive::study::test::scenarios() + "/smc_bl_jerk_limited.yaml";
  const fs::path out = scratch() / "warn";
  // 10 ms: both moves (about a second) are cut off; 500 m/s is mm/s meant.
  const ProcResult r = study(scen + " --sweep reference.max_velocity=0.2,500 --set duration=0.01 --out " +
                             out.string() + " -j 2 --no-plots");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("[warning] reference.max_velocity: 500 m/s"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("mm/s? (1 of 2 cases)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("[warning] 2 of 2 cases did not finish their move"), std::string::npos) << r.err;
  const std::string md = slurp(out / "report.md");
  EXPECT_NE(md.find("## Warnings"), std::string::npos) << md;
  EXPECT_NE(md.find("**2 of 2 cases did not finish their move**"), std::string::npos) << md;
  const std::string csv = slurp(out / "results.csv");
  EXPECT_NE(csv.find(",ok,error,move_finished,warnings,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",true,,false,\"reference"), std::string::npos) << csv;
  // A rerun reuses the cases (format 2 files) and reports the same.
  const ProcResult again = study(scen + " --sweep reference.max_velocity=0.2,500 --set duration=0.01 --out " +
                                 out.string() + " -j 2 --no-plots");
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_NE(again.err.find("(0 run, 2 reused)"), std::string::npos) << again.err;
  EXPECT_EQ(slurp(out / "results.csv"), csv);
  EXPECT_NE(again.err.find("mm/s? (1 of 2 cases)"), std::string::npos) << again.err;
}

// F17: a study file given to --sweep, and one key swept twice: exit 2, one line naming it.
TEST(StudyCli, SweepRefusesAStudyFileAndAKeySweptTwice) {
  const std::string scen = feeddrive::study::test::scenarios() + "/smc_bl_jerk_limited.yaml";
  const fs::path st = write_file("sweep_study.yaml", feeddrive::study::test::study_text("families: [{name: a}]\n"));
  for (const auto& [args, expected] : std::vector<std::pair<std::string, std::string>>{
           {st.string() + " --sweep plant.mass=1,2",
            "--sweep takes a scenario file, not a study file (" + st.string() + " has base/families)"},
           {scen + " --sweep plant.mass=80,100 --sweep plant.mass=1,2",
            "--sweep plant.mass and --sweep plant.mass: one key swept twice in family 'sweep'"},
           // The old spelling of the key is the key: once 2 cases, both with 3, and exit 0.
           {scen + " --sweep plant.effects.cogging_ripple.amplitude_N=1,2 --sweep "
                   "plant.effects.cogging_ripple.cogging_amplitude=3",
            "--sweep plant.effects.cogging_ripple.amplitude_N and --sweep "
            "plant.effects.cogging_ripple.cogging_amplitude (both plant.effects.cogging_ripple.cogging_amplitude): one "
            "key swept twice in family 'sweep'"}}) {
    const ProcResult b = study(args + " --out " + (scratch() / "bad_sweep2").string());
    EXPECT_EQ(b.code, 2) << args << ": " << b.err;
    EXPECT_NE(b.err.find(expected), std::string::npos) << b.err;
    EXPECT_EQ(std::count(b.err.begin(), b.err.end(), '\n'), 1) << b.err;
  }
}

// --list with a key in its old spelling: the cases are listed with the values (issue 22's review:
// the lookup by the written spelling failed with "error: map::at", exit 2).
TEST(StudyCli, ListShowsAnOldSpellingsValues) {
  const std::string scen = feeddrive::study::test::scenarios() + "/smc_bl_jerk_limited.yaml";
  const fs::path out = scratch() / "list_old_spelling.txt";
  const int status = std::system(
      (kStudy + " " + scen + " --list --sweep plant.effects.cogging_ripple.amplitude_N=1,2 > " + out.string() + " 2>&1")
          .c_str());
  const std::string text = slurp(out);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << text;
  EXPECT_NE(text.find("plant.effects.cogging_ripple.amplitude_N=1"), std::string::npos) << text;
  EXPECT_NE(text.find("plant.effects.cogging_ripple.amplitude_N=2"), std::string::npos) << text;
  EXPECT_EQ(text.find("map::at"), std::string::npos) << text;
}
}  // namespace
