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
  EXPECT_EQ(error_of("name: \"abc\n" + kTail),
            "s.yaml: line 1: YAML syntax error: a quote opened here is never closed");
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
  EXPECT_EQ(error_of(kTail + "plant:\n  mass: 1\n  mass: 2\n"),
            "s.yaml: line 6: plant.mass: duplicate key on lines 5 and 6");
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
  EXPECT_EQ(parse_scenario("name: Schleifen \xc3\xa4 \xe2\x80\x94 ok\n" + kTail).name,
            "Schleifen \xc3\xa4 \xe2\x80\x94 ok");
  EXPECT_EQ(parse_scenario("name: " + std::string(kMaxNameBytes, 'x') + "\n" + kTail).name.size(), kMaxNameBytes);
}

// Issue 19, point 8: yaml-cpp makes an alias the very node of its anchor, so an alias inside its
// own anchor is a cycle that every traversal followed until the stack overflowed (exit 139). The
// loader refuses it, and merge keys, from the parser's events, at the alias's or key's own place.
TEST(YamlStrict, RecursiveAliasIsRefusedAtTheAlias) {
  EXPECT_EQ(error_of(kTail + "friction: &f {model: lugre, inner: *f}\n"),
            "s.yaml: line 4, column 36: friction.inner: recursive YAML alias *f inside its own anchor &f (line 4): not "
            "supported (an alias may only repeat a finished node)");
  // In a list, deeper down, and through an ancestor rather than the node itself.
  EXPECT_EQ(error_of(kTail + "k: &s [1, [2, *s]]\n"),
            "s.yaml: line 4, column 15: k[1][1]: recursive YAML alias *s inside its own anchor &s (line 4): not "
            "supported (an alias may only repeat a finished node)");
  EXPECT_EQ(error_of(kTail + "plant: &p\n  mass: 1\n  friction:\n    inner: [*p]\n"),
            "s.yaml: line 7, column 13: plant.friction.inner[0]: recursive YAML alias *p inside its own anchor &p "
            "(line 4): not supported (an alias may only repeat a finished node)");
  // The root itself.
  EXPECT_NE(error_of("&r\n" + kTail + "x: *r\n").find("x: recursive YAML alias *r"), std::string::npos);
}

TEST(YamlStrict, MergeKeyIsRefusedAtTheKey) {
  EXPECT_EQ(error_of(kTail + "a: &a {x: 1}\nb:\n  <<: *a\n  y: 2\n"),
            "s.yaml: line 6, column 3: b.<<: YAML merge key (<<) not supported: write the keys out");
  EXPECT_EQ(error_of("<<: {duration: 1}\n" + kTail),
            "s.yaml: line 1, column 1: <<: YAML merge key (<<) not supported: write the keys out");
  EXPECT_NE(error_of(kTail + "plant: {<<: [{mass: 1}, {mass: 2}]}\n").find("plant.<<: YAML merge key"),
            std::string::npos);
  // A quoted '<<' is an ordinary key (YAML 1.1): the loader's unknown-key rule names it.
  EXPECT_EQ(error_of(kTail + "'<<': 1\n"), "s.yaml: <<: unknown key");
}

TEST(YamlStrict, AliasesOfFinishedNodesStillWork) {
  // An alias that repeats a finished node is no cycle: it loads like the written-out copy.
  const Scenario a =
      parse_scenario(kTail + "plant: {friction: {model: lugre, static_force: &v 150, coulomb_force: *v}}\n");
  EXPECT_EQ(a.plant.friction.static_force, 150.0);
  EXPECT_EQ(a.plant.friction.coulomb_force, 150.0);
}

}  // namespace
}  // namespace feeddrive::sim
