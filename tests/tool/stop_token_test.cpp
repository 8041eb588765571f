// The interrupt as libraries read it (feeddrive/common/interrupt.hpp): a StopToken on a flag, and
// the process's token that tool::install_interrupt_handlers' handler sets (a real SIGINT, raised
// in this process).
#include <gtest/gtest.h>

#include <csignal>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/tool/main.hpp"

namespace feeddrive::interrupt {
namespace {

TEST(StopToken, ADefaultTokenNeverStops) {
  const StopToken t;
  EXPECT_FALSE(t.stop_requested());
  EXPECT_EQ(t.signal(), 0);
  EXPECT_NO_THROW(t.check());
  EXPECT_FALSE(t.renewed().stop_requested());
}

// A token sees the flag's signal; check() throws Interrupted with the exit code 128 + signal.
TEST(StopToken, SeesTheFlagAndThrowsInterrupted) {
  StopFlag flag;
  const StopToken t(&flag);
  EXPECT_FALSE(t.stop_requested());
  flag.signal = SIGTERM;
  flag.count = flag.count + 1;
  EXPECT_EQ(t.signal(), SIGTERM);
  try {
    t.check();
    FAIL() << "no throw";
  } catch (const Interrupted& e) {
    EXPECT_EQ(e.signal(), SIGTERM);
    EXPECT_EQ(e.exit_code(), 128 + SIGTERM);
    EXPECT_STREQ(e.what(), "interrupted by SIGTERM");
  }
  EXPECT_STREQ(Interrupted(SIGINT, "; nothing written").what(), "interrupted by SIGINT; nothing written");
}

// renewed(): the signals so far are ignored (the monitor still writes its record), a second one
// stops that too; the original token still sees the first.
TEST(StopToken, RenewedIgnoresThePastAndSeesTheNextSignal) {
  StopFlag flag;
  const StopToken t(&flag);
  flag.signal = SIGINT;
  flag.count = flag.count + 1;
  const StopToken r = t.renewed();
  EXPECT_FALSE(r.stop_requested());
  EXPECT_TRUE(t.stop_requested());
  flag.signal = SIGINT;
  flag.count = flag.count + 1;
  EXPECT_EQ(r.signal(), SIGINT);
}

// The process's token: after install_interrupt_handlers a real SIGINT sets it (and does not end
// the process); a token made later still sees it.
TEST(StopToken, TheProcessTokenIsSetByTheSignalHandler) {
  const StopToken before = tool::stop_token();
  EXPECT_FALSE(before.stop_requested());
  tool::install_interrupt_handlers();
  ASSERT_EQ(std::raise(SIGINT), 0);
  EXPECT_EQ(before.signal(), SIGINT);
  EXPECT_EQ(tool::stop_token().signal(), SIGINT);
  EXPECT_THROW(tool::stop_token().check(), Interrupted);
}

}  // namespace
}  // namespace feeddrive::interrupt
