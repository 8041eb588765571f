// Issue 13, points 8 and 9: what yaml-cpp lets through silently is a one-line error naming the
// line (unclosed quotes, duplicate keys), and the scenario name is bounded, printable UTF-8.
#include <gtest/gtest.h>

#include <string>

#include "feeddrive/sim/scenario.hpp"
#include "scenario_error.hpp"

namespace feeddrive::sim {
namespace {

using test::error_of;

const std::string kTail = "duration: 0.01\ncontrol_period: 1e-4\ncontroller: {type: open_loop}\n";

TEST(YamlStrict, UnclosedQuoteIsASyntaxErrorOnItsLine) {
  // yaml-cpp reads the rest of the file into the name and the error was "duration: missing".
  EXPECT_EQ(error_of("name: \"abc\n" + kTail), "s.yaml: line 1: YAML syntax error: a quote opened here is never closed");
  EXPECT_EQ(error_of(kTail + "name: 'abc\n"), "s.yaml: line 4: YAML syntax error: a quote opened here is never closed");
  // Closed on a later line: legal YAML, but it swallows the keys in between.
  EXPECT_EQ(error_of("name: \"abc\n" + kTail + "reference: {type: \"none\"}\n"),
            "s.yaml: line 1: YAML syntax error: a quote opened here closes only on line 5 (a quoted value must end "
            "on the line where it starts)");
}

TEST(YamlStrict, QuotesInsidePlainValuesCommentsAndBlockScalarsAreNotQuotes) {
  EXPECT_NO_THROW(parse_scenario("name: it's Bob's run  # a \"comment\n" + kTail));
  EXPECT_NO_THROW(parse_scenario("name: 'it''s'\n" + kTail));
  EXPECT_NO_THROW(parse_scenario("name: \"a \\\" quote\"\n" + kTail));
  EXPECT_NO_THROW(parse_scenario(kTail + "reference: {type: 'none'}\n"));
  EXPECT_NO_THROW(parse_scenario("name: >-\n  it's a \"block\n" + kTail));
}

TEST(YamlStrict, DuplicateKeysNameTheKeyAndBothLines) {
  EXPECT_EQ(error_of("duration: 0.01\n" + kTail), "s.yaml: line 2: duration: duplicate key on lines 1 and 2");
  EXPECT_EQ(error_of(kTail + "plant:\n  mass: 1\n  friction: {model: none, model: lugre}\n"),
            "s.yaml: line 6: plant.friction.model: duplicate key on lines 6 and 6");
  EXPECT_EQ(error_of(kTail + "plant:\n  mass: 1\n  mass: 2\n"), "s.yaml: line 6: plant.mass: duplicate key on lines 5 and 6");
}

TEST(YamlStrict, ExplodingAliasesAreRefused) {
  std::string y = "a0: &a0 [1, 1, 1, 1, 1, 1, 1, 1]\n";
  for (int k = 1; k < 12; ++k)
    y += "a" + std::to_string(k) + ": &a" + std::to_string(k) + " [*a" + std::to_string(k - 1) + ", *a" +
         std::to_string(k - 1) + ", *a" + std::to_string(k - 1) + "]\n";
  EXPECT_EQ(error_of(y + kTail), "s.yaml: more than 100000 YAML nodes (aliases that expand too far?)");
}

TEST(YamlStrict, NameIsBoundedPrintableUtf8) {
  EXPECT_EQ(error_of("name: \"ab\xff\xfe\"\n" + kTail),
            "s.yaml: name: byte 3 (0xFF) is not printable UTF-8 (control character or malformed sequence)");
  EXPECT_EQ(error_of("name: \"a\\tb\"\n" + kTail),
            "s.yaml: name: byte 2 (0x09) is not printable UTF-8 (control character or malformed sequence)");
  EXPECT_EQ(error_of("name: " + std::string(kMaxNameBytes + 1, 'x') + "\n" + kTail),
            "s.yaml: name: 257 bytes: too long (at most 256)");
  EXPECT_EQ(parse_scenario("name: Schleifen \xc3\xa4 \xe2\x80\x94 ok\n" + kTail).name, "Schleifen \xc3\xa4 \xe2\x80\x94 ok");
  EXPECT_EQ(parse_scenario("name: " + std::string(kMaxNameBytes, 'x') + "\n" + kTail).name.size(), kMaxNameBytes);
}

}  // namespace
}  // namespace feeddrive::sim
