// feeddrive::output (common/output): the one escaping rule for text in gnuplot scripts, the
// gnuplot runner, and the output folder (checked before any work, staged, swapped into place,
// never replacing what feeddrive did not write).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "../support/scratch.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/output/gnuplot.hpp"

namespace {
namespace fs = std::filesystem;
using feeddrive::output::check_output_dir;
using feeddrive::output::gnuplot_string;
using feeddrive::output::is_feeddrive_output;
using feeddrive::output::kMarkerFile;
using feeddrive::output::normalise;
using feeddrive::output::StagedFolder;
using feeddrive::test_support::names;
using feeddrive::test_support::slurp;

fs::path scratch() {
  static const fs::path dir = feeddrive::test_support::make_scratch("output");
  return dir;
}

// A fresh folder for one test.
fs::path fresh(const std::string& name) {
  const fs::path d = scratch() / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void put(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

// The message of the std::invalid_argument that f throws ("" if none).
template <typename F>
std::string refusal(F f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// ---------------------------------------------------------------- the escaping rule

// The text between the quotes of a gnuplot_string result.
std::string inner(const std::string& quoted) {
  EXPECT_GE(quoted.size(), 2u);
  EXPECT_EQ(quoted.front(), '"');
  EXPECT_EQ(quoted.back(), '"');
  return quoted.substr(1, quoted.size() - 2);
}

// Nothing gnuplot interprets inside a double-quoted string, and nothing that ends it.
void expect_inert(const std::string& quoted) {
  const std::string in = inner(quoted);
  for (char c : std::string("\"'\\`@$\n\r\t{}\0", 13))
    EXPECT_EQ(in.find(c), std::string::npos) << "char " << int(c) << " in " << quoted;
  for (unsigned char c : in) EXPECT_TRUE(c >= 0x20 && c != 0x7f) << quoted;
}

TEST(GnuplotString, KeepsPlainText) {
  EXPECT_EQ(gnuplot_string("smc_jerk_limited (sat, 10 kHz) x=1.5e-3 #2 [mm/s^2] 50% a/b <c>|~!?*&;:+-"),
            "\"smc_jerk_limited (sat, 10 kHz) x=1.5e-3 #2 [mm/s^2] 50% a/b <c>|~!?*&;:+-\"");
  EXPECT_EQ(gnuplot_string(""), "\"\"");
}

TEST(GnuplotString, ReplacesEveryCharacterGnuplotInterprets) {
  EXPECT_EQ(gnuplot_string("x'; system 'touch F'; print '"), "\"x?; system ?touch F?; print ?\"");
  EXPECT_EQ(gnuplot_string("a\"b"), "\"a?b\"");                  // ends the literal
  EXPECT_EQ(gnuplot_string("a\\\"b"), "\"a??b\"");               // escaped quote
  EXPECT_EQ(gnuplot_string("\\n\\042\\x41"), "\"?n?042?x41\"");  // escape sequences
  EXPECT_EQ(gnuplot_string("`touch F`"), "\"?touch F?\"");       // command substitution
  EXPECT_EQ(gnuplot_string("@macro"), "\"?macro\"");             // macro
  EXPECT_EQ(gnuplot_string("$HOME ${x}"), "\"?HOME ??x?\"");
  EXPECT_EQ(gnuplot_string("a\nset output '/etc/x'\nb"), "\"a?set output ?/etc/x??b\"");
  EXPECT_EQ(gnuplot_string(std::string("a\0b\r\t\x7f", 6)), "\"a?b???\"");
  EXPECT_EQ(gnuplot_string("system(\"touch F\")"), "\"system(?touch F?)\"");  // plain text inside the literal
}

TEST(GnuplotString, Utf8KeptMalformedBytesReplaced) {
  EXPECT_EQ(gnuplot_string("\xC2\xB5m \xC3\xBC \xE2\x82\xAC \xF0\x9F\x98\x80"),
            "\"\xC2\xB5m \xC3\xBC \xE2\x82\xAC \xF0\x9F\x98\x80\"");
  EXPECT_EQ(gnuplot_string("\xFF\xFE"), "\"??\"");            // not UTF-8
  EXPECT_EQ(gnuplot_string("\xC0\xA7"), "\"??\"");            // overlong '
  EXPECT_EQ(gnuplot_string("\xE0\x80\xA2"), "\"???\"");       // overlong "
  EXPECT_EQ(gnuplot_string("\xC2\x85"), "\"??\"");            // C1 control (NEL)
  EXPECT_EQ(gnuplot_string("\xED\xA0\x80"), "\"???\"");       // surrogate
  EXPECT_EQ(gnuplot_string("\xF4\x90\x80\x80"), "\"????\"");  // above U+10FFFF
  EXPECT_EQ(gnuplot_string("\xE2\x82"), "\"??\"");            // cut short
  EXPECT_EQ(gnuplot_string("\xC3"), "\"?\"");
}

TEST(GnuplotString, LengthIsCappedAtACharacterBoundary) {
  EXPECT_EQ(gnuplot_string(std::string(500, 'a')), "\"" + std::string(200, 'a') + "...\"");
  EXPECT_EQ(gnuplot_string("ab\xC3\xBC", 3), "\"ab...\"");
  EXPECT_EQ(gnuplot_string("abc", 3), "\"abc\"");
}

TEST(GnuplotString, RandomBytesAreAlwaysInert) {
  std::mt19937 rng(2024);
  for (int trial = 0; trial < 20000; ++trial) {
    std::string s(rng() % 40, '\0');
    for (char& c : s) c = static_cast<char>(rng() & 0xff);
    expect_inert(gnuplot_string(s));
    if (HasFailure()) break;
  }
}

// The rule against gnuplot itself: every hostile text, quoted, is printed as text and runs nothing.
TEST(GnuplotString, RealGnuplotPrintsItAndRunsNothing) {
  const fs::path dir = fresh("gp real");
  const fs::path mark = dir / "MARK";
  const std::string m = mark.string();
  const std::vector<std::string> hostile = {
      "x'; system 'touch " + m + "'; print '",
      "x\"; system \"touch " + m + "\"; print \"",
      "`touch " + m + "`",
      "x\\\"; system \\\"touch " + m + "\\\"; print \\\"",
      "@cmd",
      "a\nsystem 'touch " + m + "'\n",
      "\xC0\xA2; system \xC0\xA2touch " + m + "\xC0\xA2",
      "system(\"touch " + m + "\")",
  };
  std::string script = "cmd = \"system('touch " + m + "')\"\nset print 'printed.txt'\n";
  std::string expected;
  for (const auto& h : hostile) {
    const std::string q = gnuplot_string(h);
    script += "print " + q + "\nset title " + q + "\n";
    expected += inner(q) + "\n";
  }
  ASSERT_NO_THROW(feeddrive::output::run_gnuplot(dir, script, {})) << script;
  EXPECT_FALSE(fs::exists(mark)) << "a quoted text ran a command";
  EXPECT_EQ(slurp(dir / "printed.txt"), expected);
  EXPECT_FALSE(fs::exists(dir / "gnuplot.log")) << "removed on success";
  EXPECT_TRUE(fs::exists(dir / "plots.gp"));
}

TEST(RunGnuplot, NoShellAndOneLineErrors) {
  // A folder name a shell would execute: gnuplot runs there all the same, and nothing else runs.
  const fs::path dir = fresh("q'; touch SHELLMARK; '");
  ASSERT_NO_THROW(feeddrive::output::run_gnuplot(dir, "set print 'ok.txt'\nprint 1+1\n", {}));
  EXPECT_EQ(slurp(dir / "ok.txt"), "2\n");
  EXPECT_FALSE(fs::exists("SHELLMARK"));
  EXPECT_FALSE(fs::exists(scratch() / "SHELLMARK"));
  try {
    feeddrive::output::run_gnuplot(dir, "print 1\nplot 'no_such_file.csv' using 1:2\n", {});
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("gnuplot failed"), std::string::npos) << w;
    EXPECT_NE(w.find("plots.gp\" line 2"), std::string::npos) << "gnuplot's last message: " << w;
    EXPECT_EQ(w.find('\n'), std::string::npos) << w;
  }
}

// ---------------------------------------------------------------- the output folder

TEST(OutputFolder, NormalisesAndRefusesPathsWithoutAFolderOfTheirOwn) {
  EXPECT_EQ(normalise("prev/"), fs::path("prev"));
  EXPECT_EQ(normalise("prev///"), fs::path("prev"));
  EXPECT_EQ(normalise("./a/./b/"), fs::path("a/b"));
  EXPECT_EQ(normalise("a/x/../b"), fs::path("a/b"));
  EXPECT_EQ(normalise("/x/y/"), fs::path("/x/y"));
  EXPECT_EQ(normalise("../y"), fs::path("../y"));
  for (const std::string bad : {"", "/", "//", ".", "./", "..", "../", "a/..", "../..", "/.."}) {
    const std::string why = refusal([&] { normalise(bad); });
    EXPECT_EQ(why.rfind("--out ", 0), 0u) << "[" << bad << "] " << why;
    EXPECT_EQ(why.find('\n'), std::string::npos) << why;
  }
  EXPECT_NE(refusal([] { normalise(""); }).find("--out \"\": empty"), std::string::npos);
  EXPECT_NE(refusal([] { normalise("."); }).find("--out .: names no folder"), std::string::npos);
  EXPECT_EQ(refusal([] { normalise("", "--results"); }).rfind("--results \"\": ", 0), 0u) << "names the option";
}

TEST(OutputFolder, MarkerOnly) {
  const fs::path d = fresh("marker");
  EXPECT_FALSE(is_feeddrive_output(d));
  put(d / "summary.json", "{}");
  put(d / "findings.json", "{}");
  EXPECT_FALSE(is_feeddrive_output(d)) << "summary.json or findings.json is not a marker";
  put(d / kMarkerFile, "");
  EXPECT_FALSE(is_feeddrive_output(d));
  put(d / kMarkerFile, "feeddrive-output\n");
  EXPECT_FALSE(is_feeddrive_output(d));
  put(d / kMarkerFile, "feeddrive-output\nformat: x\ntool: feeddrive-sim\n");
  EXPECT_FALSE(is_feeddrive_output(d));
  put(d / kMarkerFile, "feeddrive\nformat: 1\ntool: feeddrive-sim\n");
  EXPECT_FALSE(is_feeddrive_output(d));
  put(d / kMarkerFile, feeddrive::output::marker_text("feeddrive-sim"));
  EXPECT_TRUE(is_feeddrive_output(d));
  // a folder or a symbolic link named like the marker is not one
  const fs::path e = fresh("marker_dir");
  fs::create_directories(e / kMarkerFile);
  EXPECT_FALSE(is_feeddrive_output(e));
  const fs::path l = fresh("marker_link");
  fs::create_symlink(d / kMarkerFile, l / kMarkerFile);
  EXPECT_FALSE(is_feeddrive_output(l));
  // nor is a link to a marked folder
  fs::create_symlink(d, scratch() / "link_to_marked");
  EXPECT_FALSE(is_feeddrive_output(scratch() / "link_to_marked"));
}

TEST(OutputFolder, CheckAcceptsAbsentEmptyAndEarlierOutputs) {
  const fs::path base = fresh("check_ok");
  EXPECT_EQ(check_output_dir((base / "new").string()), base / "new");
  EXPECT_EQ(check_output_dir((base / "not/yet/there/").string()), base / "not/yet/there");  // parents are made later
  fs::create_directories(base / "empty");
  EXPECT_NO_THROW(check_output_dir((base / "empty").string()));
  fs::create_directories(base / "earlier");
  put(base / "earlier" / kMarkerFile, feeddrive::output::marker_text("feeddrive-fit"));
  put(base / "earlier" / "findings.json", "{}");
  EXPECT_NO_THROW(check_output_dir((base / "earlier/").string()));
  EXPECT_EQ(names(base), (std::vector<std::string>{"earlier", "empty"})) << "the check leaves nothing behind";
}

TEST(OutputFolder, CheckRefusesWithOneLineNamingTheValue) {
  const fs::path base = fresh("check_bad");
  // a user's folder with a fake summary.json, and one with a fake findings.json
  fs::create_directories(base / "user");
  put(base / "user" / "thesis.tex", "keep me");
  put(base / "user" / "summary.json", "not json at all");
  fs::create_directories(base / "user2");
  put(base / "user2" / "findings.json", "{}");
  put(base / "file", "a file");
  fs::create_symlink(base / "user", base / "link");
  const std::string long_name(250, 'n');
  const std::vector<std::pair<std::string, std::string>> cases = {
      {(base / "user").string(), "not a feeddrive output"},
      {(base / "user/").string(), "not a feeddrive output"},
      {(base / "user2").string(), "not a feeddrive output"},
      {(base / "file").string(), "exists and is not a folder"},
      {(base / "file/out").string(), "is not a folder"},
      {(base / "file/a/b/").string(), "is not a folder"},
      {(base / "link").string(), "symbolic link"},
      {(base / long_name).string(), "too long"},
      {(base / "x" / std::string(3000, 'y') / std::string(2000, 'z')).string(), "too long"},
  };
  for (const auto& [value, why] : cases) {
    const std::string w = refusal([&] { check_output_dir(value); });
    EXPECT_EQ(w.rfind("--out " + value.substr(0, 50), 0), 0u) << w;
    EXPECT_NE(w.find(why), std::string::npos) << value.substr(0, 80) << ": " << w;
    EXPECT_EQ(w.find('\n'), std::string::npos) << w;
  }
  EXPECT_EQ(slurp(base / "user" / "thesis.tex"), "keep me");
  EXPECT_EQ(names(base / "user"), (std::vector<std::string>{"summary.json", "thesis.tex"}));
  // a control character in the value does not break the one line
  const std::string w = refusal([&] { check_output_dir((base / "file").string() + "\n/x"); });
  EXPECT_EQ(w.find('\n'), std::string::npos) << w;
}

TEST(OutputFolder, CheckRefusesAFolderItCannotWriteIn) {
  const fs::path base = fresh("check_ro");
  fs::create_directories(base / "ro");
  fs::permissions(base / "ro", fs::perms::owner_read | fs::perms::owner_exec);
  if (::geteuid() == 0) {
    fs::permissions(base / "ro", fs::perms::owner_all);
    GTEST_SKIP() << "root writes into a read-only folder; covered by the probe and the cases above";
  }
  const std::string w = refusal([&] { check_output_dir((base / "ro" / "out").string()); });
  fs::permissions(base / "ro", fs::perms::owner_all);
  EXPECT_NE(w.find("cannot write in"), std::string::npos) << w;
}

TEST(OutputFolder, StagedCommitCreatesAMarkedFolder) {
  const fs::path base = fresh("staged_new");
  {
    StagedFolder out((base / "a/b/run/").string(), "test-tool");
    EXPECT_EQ(out.target(), base / "a/b/run");
    EXPECT_EQ(out.dir().parent_path(), base / "a/b");
    EXPECT_TRUE(is_feeddrive_output(out.dir())) << "marked from the start";
    put(out.dir() / "result.txt", "new");
    EXPECT_TRUE(out.commit().empty());  // no warning
  }
  EXPECT_EQ(slurp(base / "a/b/run/result.txt"), "new");
  EXPECT_TRUE(is_feeddrive_output(base / "a/b/run"));
  EXPECT_NE(slurp(base / "a/b/run" / kMarkerFile).find("tool: test-tool"), std::string::npos);
  EXPECT_EQ(names(base / "a/b"), std::vector<std::string>{"run"}) << "no temporary folder left";
}

TEST(OutputFolder, AnIncompleteRecordNeverReplacesAnEarlierOutput) {
  // The monitor's record of an interrupted rerun once replaced a complete earlier output.
  const fs::path base = fresh("keep_earlier");
  {
    StagedFolder out((base / "run").string(), "test-tool");
    put(out.dir() / "result.txt", "complete");
    EXPECT_EQ(out.commit_keeping_earlier("incomplete"), base / "run");  // nothing there: the target
  }
  fs::create_directory(base / "run.incomplete-1");  // an empty folder is not taken either
  for (const char* expect : {"run.incomplete-2", "run.incomplete-3"}) {
    StagedFolder out((base / "run").string(), "test-tool");
    put(out.dir() / "result.txt", expect);
    EXPECT_EQ(out.commit_keeping_earlier("incomplete"), base / expect);
  }
  EXPECT_EQ(slurp(base / "run/result.txt"), "complete");
  EXPECT_EQ(slurp(base / "run.incomplete-2/result.txt"), "run.incomplete-2");
  EXPECT_EQ(slurp(base / "run.incomplete-3/result.txt"), "run.incomplete-3");
  EXPECT_TRUE(is_feeddrive_output(base / "run.incomplete-3"));
  EXPECT_TRUE(fs::is_empty(base / "run.incomplete-1"));
  EXPECT_EQ(names(base), (std::vector<std::string>{"run", "run.incomplete-1", "run.incomplete-2", "run.incomplete-3"}))
      << "no temporary folder left";
}

TEST(OutputFolder, TrailingSlashReplacesAnEarlierOutputSafely) {
  const fs::path base = fresh("staged_replace");
  {
    StagedFolder first((base / "prev").string(), "t");
    put(first.dir() / "old.txt", "old");
    EXPECT_TRUE(first.commit().empty());  // no warning
  }
  put(base / "neighbour.txt", "mine");
  {
    StagedFolder second((base / "prev/").string(), "t");
    EXPECT_EQ(second.dir().parent_path(), base) << "a sibling, not inside prev";
    put(second.dir() / "new.txt", "new");
    EXPECT_TRUE(second.commit().empty());  // no warning
  }
  EXPECT_EQ(names(base / "prev"), (std::vector<std::string>{kMarkerFile, "new.txt"}));
  EXPECT_EQ(names(base), (std::vector<std::string>{"neighbour.txt", "prev"}));
}

TEST(OutputFolder, AUsersFileInAnEarlierOutputIsNeverDeleted) {
  const fs::path base = fresh("staged_foreign");
  {
    StagedFolder first((base / "prev").string(), "t");
    put(first.dir() / "old.txt", "old");
    EXPECT_TRUE(first.commit().empty());  // no warning
  }
  // the marker lists what was written
  EXPECT_NE(slurp(base / "prev" / kMarkerFile).find("files:\nfile: old.txt\n"), std::string::npos)
      << slurp(base / "prev" / kMarkerFile);
  EXPECT_EQ(feeddrive::output::foreign_entry(base / "prev"), "");
  EXPECT_NO_THROW(check_output_dir((base / "prev").string()));
  // a file of the user's: refused before any work, with its name
  put(base / "prev" / "notes.txt", "mine");
  EXPECT_EQ(feeddrive::output::foreign_entry(base / "prev"), "notes.txt");
  const std::string w = refusal([&] { check_output_dir((base / "prev/").string()); });
  EXPECT_NE(w.find("holds 'notes.txt', which feeddrive did not write"), std::string::npos) << w;
  EXPECT_THROW(StagedFolder((base / "prev").string(), "t"), std::invalid_argument);
  EXPECT_EQ(slurp(base / "prev" / "notes.txt"), "mine");
  // ... or put there while the next run was going: not replaced, the results kept aside
  fs::remove(base / "prev" / "notes.txt");
  {
    StagedFolder second((base / "prev").string(), "t");
    put(second.dir() / "new.txt", "new");
    fs::create_directories(base / "prev" / "mine");
    try {
      (void)second.commit();  // throws
      FAIL() << "replaced an output holding a user's folder";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("holds files feeddrive did not write"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(second.dir().string()), std::string::npos) << e.what();
    }
    EXPECT_EQ(slurp(second.dir() / "new.txt"), "new");
  }
  EXPECT_EQ(names(base / "prev"), (std::vector<std::string>{kMarkerFile, "mine", "old.txt"}));
  // An output whose marker has no list (feeddrive before the list) is replaced whole, as before.
  const fs::path older = fresh("staged_older") / "run";
  fs::create_directories(older);
  put(older / kMarkerFile, feeddrive::output::marker_text("feeddrive-sim"));
  put(older / "summary.json", "{}");
  EXPECT_EQ(feeddrive::output::foreign_entry(older), "");
  {
    StagedFolder next(older.string(), "t");
    EXPECT_TRUE(next.commit().empty());  // no warning
  }
  EXPECT_EQ(names(older), std::vector<std::string>{kMarkerFile});
  // A folder committed without the list (feeddrive-study's, which grows over reruns) takes new
  // entries without becoming foreign.
  const fs::path growing = fresh("staged_growing") / "study";
  {
    StagedFolder s(growing.string(), "feeddrive-study");
    EXPECT_TRUE(s.commit(false).empty());  // no warning
  }
  put(growing / "results.csv", "a\n");
  EXPECT_EQ(feeddrive::output::foreign_entry(growing), "");
}

TEST(OutputFolder, AnotherOutputOfTheRunMustLieOutsideTheFolder) {
  // feeddrive-launch --out out/run --lcm-log out/run/run.lcmlog: the log would be written into the
  // folder that the run replaces at its end (and lost with the earlier output).
  using feeddrive::output::check_outside;
  const fs::path base = fresh("outside");
  EXPECT_NO_THROW(check_outside("", "--lcm-log", (base / "run").string()));
  EXPECT_NO_THROW(check_outside((base / "run.lcmlog").string(), "--lcm-log", (base / "run").string()));
  EXPECT_NO_THROW(check_outside((base / "run2/x.lcmlog").string(), "--lcm-log", (base / "run").string()));
  for (const std::string f : {"run/run.lcmlog", "run/sub/x.lcmlog", "other/../run/x.lcmlog"}) {
    const std::string w = refusal([&] { check_outside((base / f).string(), "--lcm-log", (base / "run/").string()); });
    EXPECT_EQ(w.rfind("--lcm-log " + (base / f).string() + ": lies inside --out", 0), 0u) << w;
  }
  EXPECT_NE(
      refusal([&] { check_outside((base / "run").string(), "--lcm-log", (base / "run").string()); }).find("itself"),
      std::string::npos);
}

TEST(OutputFolder, FailureBeforeCommitKeepsThePreviousOutput) {
  const fs::path base = fresh("staged_fail");
  {
    StagedFolder first((base / "prev").string(), "t");
    put(first.dir() / "old.txt", "old");
    EXPECT_TRUE(first.commit().empty());  // no warning
  }
  try {
    StagedFolder second((base / "prev/").string(), "t");
    put(second.dir() / "half.txt", "half");
    throw std::runtime_error("the run failed");
  } catch (const std::runtime_error&) {}
  EXPECT_EQ(slurp(base / "prev" / "old.txt"), "old");
  EXPECT_EQ(names(base), std::vector<std::string>{"prev"}) << "the temporary folder is removed";
}

TEST(OutputFolder, TargetTakenByTheUserDuringTheRunIsNotReplaced) {
  const fs::path base = fresh("staged_race");
  // absent at the start, a user's folder at the end
  {
    StagedFolder out((base / "run").string(), "t");
    put(out.dir() / "result.txt", "new");
    fs::create_directories(base / "run");
    put(base / "run" / "mine.txt", "mine");
    try {
      (void)out.commit();  // throws
      FAIL() << "replaced a user's folder";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(out.dir().string()), std::string::npos) << "names where the results are";
    }
    EXPECT_EQ(slurp(out.dir() / "result.txt"), "new") << "the results are kept";
  }
  EXPECT_EQ(names(base / "run"), std::vector<std::string>{"mine.txt"});
  // an earlier output at the start, a user's file at the end
  fs::remove_all(base);
  fs::create_directories(base);
  {
    StagedFolder first((base / "run").string(), "t");
    EXPECT_TRUE(first.commit().empty());  // no warning
  }
  {
    StagedFolder out((base / "run").string(), "t");
    fs::remove_all(base / "run");
    put(base / "run", "a file now");
    EXPECT_THROW((void)out.commit(), std::runtime_error);
  }
  EXPECT_EQ(slurp(base / "run"), "a file now");
}

TEST(OutputFolder, StagedRefusesBeforeCreatingAnything) {
  const fs::path base = fresh("staged_refuse");
  fs::create_directories(base / "user");
  put(base / "user" / "summary.json", "{}");
  put(base / "user" / "keep.txt", "keep");
  EXPECT_THROW(StagedFolder((base / "user/").string(), "t"), std::invalid_argument);
  EXPECT_EQ(names(base), std::vector<std::string>{"user"});
  EXPECT_EQ(names(base / "user"), (std::vector<std::string>{"keep.txt", "summary.json"}));
}

TEST(OutputFolder, RemoveOutputOnlyRemovesFeeddriveOutputs) {
  const fs::path base = fresh("remove");
  fs::create_directories(base / "user");
  put(base / "user" / "a.txt", "a");
  EXPECT_FALSE(feeddrive::output::remove_output(base / "user"));
  EXPECT_TRUE(fs::exists(base / "user" / "a.txt"));
  fs::create_directories(base / "empty");
  EXPECT_TRUE(feeddrive::output::remove_output(base / "empty"));
  fs::create_directories(base / "ours");
  put(base / "ours" / kMarkerFile, feeddrive::output::marker_text("t"));
  put(base / "ours" / "x", "x");
  EXPECT_TRUE(feeddrive::output::remove_output(base / "ours"));
  EXPECT_EQ(names(base), std::vector<std::string>{"user"});
}

}  // namespace
