#include <unistd.h>
// The one mapping from errors to exit codes of every tool (common/tool/include/feeddrive/tool/main.hpp):
// pure logic.
#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "feeddrive/common/errors.hpp"
#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/tool/main.hpp"

namespace feeddrive::tool {
namespace {

template <typename E>
int code_of(const E& e) {
  return report(std::make_exception_ptr(e));
}

TEST(ToolReport, EachErrorKindHasItsExitCodeAndOneLine) {
  setup_logging("test_tool", false);
  testing::internal::CaptureStderr();
  EXPECT_EQ(code_of(BadInput("plant.mass = -1: must be > 0")), kExitBadInput);
  EXPECT_EQ(std::string(testing::internal::GetCapturedStderr()), "error: plant.mass = -1: must be > 0\n");
  testing::internal::CaptureStderr();
  EXPECT_EQ(code_of(std::invalid_argument("--out: not a feeddrive output")), kExitBadInput);
  EXPECT_EQ(std::string(testing::internal::GetCapturedStderr()), "error: --out: not a feeddrive output\n");
  testing::internal::CaptureStderr();
  EXPECT_EQ(code_of(std::runtime_error("step timeout")), kExitFailed);
  // a failure of the run: one log line naming the process (setup_logging's logger)
  const std::string failed = testing::internal::GetCapturedStderr();
  EXPECT_NE(failed.find("] [test_tool] [error] step timeout"), std::string::npos) << failed;
  EXPECT_EQ(failed.find('\n'), failed.size() - 1) << failed;
  // 128 + signal, one line unless started by feeddrive-launch (it reports the interrupt once).
  ::unsetenv(interrupt::kQuietEnv);
  testing::internal::CaptureStderr();
  EXPECT_EQ(report(std::make_exception_ptr(interrupt::Interrupted(SIGINT)), "; nothing written"), 128 + SIGINT);
  EXPECT_EQ(std::string(testing::internal::GetCapturedStderr()), "error: interrupted by SIGINT; nothing written\n");
  ::setenv(interrupt::kQuietEnv, "1", 1);
  testing::internal::CaptureStderr();
  EXPECT_EQ(code_of(interrupt::Interrupted(SIGTERM)), 128 + SIGTERM);
  EXPECT_EQ(std::string(testing::internal::GetCapturedStderr()), "");
  ::unsetenv(interrupt::kQuietEnv);
}

// Under feeddrive-launch a refusal goes to the launcher's pipe (interrupt::kRefusalFdEnv), which
// prints each different line once; a failure (exit 1) still goes to stderr.
TEST(ToolReport, UnderTheLauncherARefusalGoesToItsPipe) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  ::setenv(interrupt::kRefusalFdEnv, std::to_string(fds[1]).c_str(), 1);
  testing::internal::CaptureStderr();
  EXPECT_EQ(code_of(std::invalid_argument("s.yaml: the scenario file is a FIFO")), kExitBadInput);
  EXPECT_EQ(code_of(std::runtime_error("step timeout")), kExitFailed);  // a failure: logged, not piped
  testing::internal::GetCapturedStderr();
  ::unsetenv(interrupt::kRefusalFdEnv);
  ::close(fds[1]);
  char buf[256];
  const ssize_t n = ::read(fds[0], buf, sizeof buf);
  ::close(fds[0]);
  ASSERT_GT(n, 0);
  EXPECT_EQ(std::string(buf, static_cast<std::size_t>(n)), "error: s.yaml: the scenario file is a FIFO\n");
}

TEST(ToolReport, InputStepMakesEveryErrorButAnInterruptBadInput) {
  EXPECT_THROW(input_step([]() -> int { throw std::runtime_error("yaml: bad indentation"); }), BadInput);
  EXPECT_THROW(input_step([]() -> int { throw interrupt::Interrupted(SIGINT); }), interrupt::Interrupted);
  EXPECT_EQ(input_step([] { return 7; }), 7);
}

TEST(ToolParse, HelpIsZeroAndAParseErrorIsTwoInOneLine) {
  CLI::App app{"t", "t"};
  std::string out;
  app.add_option("--out", out)->required();
  char name[] = "t", bad[] = "--nope", help[] = "--help";
  char* bad_argv[] = {name, bad};
  testing::internal::CaptureStderr();
  EXPECT_EQ(parse(app, 2, bad_argv), kExitBadInput);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(err.rfind("error: ", 0), 0u) << err;
  EXPECT_EQ(err.find('\n'), err.size() - 1) << err;  // one line
  char* help_argv[] = {name, help};
  testing::internal::CaptureStdout();
  EXPECT_EQ(parse(app, 2, help_argv), 0);
  testing::internal::GetCapturedStdout();
}

// An unknown option is named even when a required option is missing too (CLI11 reports the
// required one first: `feeddrive-sim --bogus-opt` once said only "scenario is required").
TEST(ToolParse, AnUnknownOptionIsNamedBeforeAMissingRequiredOne) {
  CLI::App app{"t", "t"};
  std::string scenario, out;
  app.add_option("scenario", scenario)->required();
  app.add_option("--out", out);
  char name[] = "t", bad[] = "--bogus-opt", file[] = "s.yaml";
  char* only_bad[] = {name, bad};
  testing::internal::CaptureStderr();
  EXPECT_EQ(parse(app, 2, only_bad), kExitBadInput);
  std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(err, "error: --bogus-opt: no such option (see --help)\n");
  CLI::App app2{"t", "t"};
  app2.add_option("scenario", scenario)->required();
  char* with_file[] = {name, file, bad};
  testing::internal::CaptureStderr();
  EXPECT_EQ(parse(app2, 3, with_file), kExitBadInput);
  err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("--bogus-opt"), std::string::npos) << err;
  EXPECT_EQ(err.find('\n'), err.size() - 1) << err;  // one line
}

// Every tool names an option it does not have the same way (review of issue 22, item 4): CLI11
// alone once said "The following argument was not expected: --bogus" when nothing was missing.
TEST(ToolParse, AnUnknownOptionIsNamedWhenNothingElseIsWrong) {
  // The exit code and what parse() printed (stderr, then stdout) for `t ARGS` of a tool with one
  // optional positional argument.
  const auto parsed = [](std::vector<std::string> args, bool speak) {
    CLI::App app{"t", "t"};
    std::string file;
    app.add_option("file", file);
    args.insert(args.begin(), "t");
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    testing::internal::CaptureStdout();
    testing::internal::CaptureStderr();
    const std::optional<int> rc = parse(app, static_cast<int>(argv.size()), argv.data(), speak);
    const std::string err = testing::internal::GetCapturedStderr();
    return std::make_pair(rc, err + testing::internal::GetCapturedStdout());
  };
  using Parsed = std::pair<std::optional<int>, std::string>;
  EXPECT_EQ(parsed({"a.yaml", "--bogus"}, true),
            Parsed(kExitBadInput, "error: --bogus: no such option (see --help)\n"));
  EXPECT_EQ(parsed({"a.yaml", "b.yaml"}, true),
            Parsed(kExitBadInput, "error: b.yaml: unexpected argument (see --help)\n"));
  // Not speaking (the MPI ranks but 0 of feeddrive-study): the same exit codes, no output.
  EXPECT_EQ(parsed({"a.yaml", "--bogus"}, false), Parsed(kExitBadInput, ""));
  EXPECT_EQ(parsed({"--help"}, false), Parsed(0, ""));
}

enum class Colour { kRed, kDarkBlue };
inline const std::vector<std::pair<Colour, const char*>>& enum_names(Colour) {
  static const std::vector<std::pair<Colour, const char*>> k{{Colour::kRed, "red"}, {Colour::kDarkBlue, "dark-blue"}};
  return k;
}

// An enum option is read through the enum's one table; any other name: "KEY = 'x': expected one
// of a, b" (exit 2).
TEST(ToolParse, AnEnumOptionTakesTheNamesOfItsTable) {
  char name[] = "t", opt[] = "--colour", blue[] = "dark-blue", bad[] = "green";
  Colour c = Colour::kRed;
  CLI::App app{"t", "t"};
  add_enum_option(app, "--colour", c, "a colour");
  char* ok[] = {name, opt, blue};
  EXPECT_EQ(parse(app, 3, ok), std::nullopt);
  EXPECT_EQ(c, Colour::kDarkBlue);
  EXPECT_NE(app.help().find("red|dark-blue"), std::string::npos) << app.help();
  CLI::App app2{"t", "t"};
  add_enum_option(app2, "--colour", c, "a colour");
  char* wrong[] = {name, opt, bad};
  testing::internal::CaptureStderr();
  EXPECT_EQ(parse(app2, 3, wrong), kExitBadInput);
  EXPECT_EQ(testing::internal::GetCapturedStderr(),
            "error: --colour = 'green': expected one of red, dark-blue (see --help)\n");
}

}  // namespace
}  // namespace feeddrive::tool
