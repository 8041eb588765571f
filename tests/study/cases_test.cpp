// Case expansion and resolution: pure functions of the study.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "feeddrive/common/fields.hpp"
#include "feeddrive/common/validate.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/study/cases.hpp"
#include "feeddrive/study/runner.hpp"
#include "study_util.hpp"

namespace feeddrive::study {
namespace {

using test::study_text;

const char* kFamilies = R"(
controllers:
  - {name: smc, scenario: SCEN/smc_bl_jerk_limited.yaml}
  - {name: cascade, controller: {type: cascade, kv: 3000}}
families:
  - name: nominal
  - name: grid
    grid:
      - {key: plant.mass, scale: [0.8, 1.2]}
      - {keys: [plant.friction.static_force, plant.friction.coulomb_force], values: [[100, 70], [150, 110], [160, 120]]}
  - name: mc
    set: {plant.sensor.quantization: 5.0e-8}
    monte_carlo:
      draws: 50
      seed: 11
      parameters:
        - {key: plant.mass, distribution: uniform, low: 0.8, high: 1.2, scale: true}
        - {keys: [plant.friction.bristle_stiffness, plant.friction.bristle_damping], distribution: lognormal, mu: 0, sigma: 0.1, scale: true}
        - {key: plant.effects.input_delay.delay, distribution: normal, mean: 5.0e-4, stddev: 3.0e-4, low: 0, high: 1.0e-3}
)";

Study families() {
  std::string t = kFamilies;
  t.replace(t.find("SCEN"), 4, test::scenarios());
  return parse_study(study_text(t), ".", "s.yaml");
}

TEST(StudyCases, ExpansionOrderAndGridMixedRadix) {
  const Study s = families();
  const auto cases = expand(s);
  ASSERT_EQ(static_cast<long>(cases.size()), s.total_cases());
  ASSERT_EQ(cases.size(), 2u * (1 + 6 + 50));
  // Controller-major, then family, grid point, draw.
  EXPECT_EQ(cases[0].controller, 0u);
  EXPECT_EQ(cases[0].family, 0u);
  EXPECT_EQ(cases[57].controller, 1u);
  // Point 4 = (mass index 1, friction index 1): the last axis runs fastest.
  const auto p4 = grid_point(s.families[1], 4);
  ASSERT_EQ(p4.size(), 3u);
  EXPECT_EQ(p4[0].key, "plant.mass");
  EXPECT_DOUBLE_EQ(p4[0].factor, 1.2);
  EXPECT_EQ(p4[1].value, "150");
  EXPECT_EQ(p4[2].value, "110");
}

// Issue 19, point 9: a case is made from its index alone (a study of 10^6 is never expanded at
// once). The same cases as the nested loops of the documented order: controller, family, grid
// point, draw.
TEST(StudyCases, CaseAtIndexIsTheDocumentedOrder) {
  const Study s = families();
  ASSERT_EQ(case_count(s), 114u);
  std::size_t i = 0;
  for (std::size_t c = 0; c < 2; ++c)
    for (std::size_t f = 0; f < 3; ++f) {
      const long points = f == 1 ? 6 : 1, draws = f == 2 ? 50 : 0;
      for (long p = 0; p < points; ++p)
        for (long d = draws > 0 ? 0 : -1; d < draws; ++d, ++i) {
          const CaseSpec cs = case_at(s, i);
          ASSERT_EQ(cs.controller, c) << i;
          ASSERT_EQ(cs.family, f) << i;
          ASSERT_EQ(cs.point, p) << i;
          ASSERT_EQ(cs.draw, d) << i;
        }
    }
  EXPECT_EQ(i, case_count(s));
  EXPECT_THROW(case_at(s, case_count(s)), std::out_of_range);
  // The variations too: case_at(113) is the last draw of the cascade's Monte Carlo family.
  const CaseSpec last = case_at(s, 113);
  ASSERT_EQ(last.variations.size(), 4u);
  EXPECT_EQ(last.variations[0].value,
            validate::format_number(draw_value(s.families[2].monte_carlo.parameters[0], 11, 49, 0)));
}

TEST(StudyCases, ProbesCoverEveryAxisValueOnceWithinTheBudget) {
  const Study s = families();
  // Per controller: nominal (0), grid (first case 1; mass value 1 = point 3, case 4: stride 3; friction
  // values 1, 2 = points 1, 2), mc (its first case 7); the cascade's the same + 57.
  const std::vector<std::size_t> want = {0, 1, 2, 3, 4, 7, 57, 58, 59, 60, 61, 64};
  EXPECT_EQ(probe_cases(s, 1000), want);
  EXPECT_EQ(probe_cases(s, 3), std::vector<std::size_t>(want.begin(), want.begin() + 3));
}

TEST(StudyCases, DrawsAreTheSameForEveryControllerAndInsideTheirBounds) {
  const Study s = families();
  const auto cases = expand(s);
  for (std::size_t i = 0; i < 50; ++i) {
    const CaseSpec& a = cases[7 + i];
    const CaseSpec& b = cases[57 + 7 + i];
    ASSERT_EQ(a.draw, static_cast<long>(i));
    ASSERT_EQ(a.variations.size(), b.variations.size());
    for (std::size_t k = 0; k < a.variations.size(); ++k) EXPECT_EQ(a.variations[k].value, b.variations[k].value);
    const double delay = a.variations.back().factor;
    EXPECT_GE(delay, 0.0);
    EXPECT_LE(delay, 1e-3);
    // Linked keys share one draw.
    EXPECT_EQ(a.variations[1].value, a.variations[2].value);
  }
}

// The distributions' moments from 20,000 draws. Standard error of the mean: sd/sqrt(n) =
// 0.0071 sd, so 4 standard errors (0.03 sd) fail a correct generator with probability ~6e-5
// (and the seed is fixed: the outcome is deterministic).
TEST(StudyCases, DistributionsHaveTheirStatedMoments) {
  const int n = 20000;
  const auto moments = [&](const DrawSpec& d) {
    double s1 = 0, s2 = 0;
    for (int j = 0; j < n; ++j) {
      const double x = draw_value(d, 42, j, 0);
      s1 += x;
      s2 += x * x;
    }
    const double mean = s1 / n;
    return std::make_pair(mean, std::sqrt(s2 / n - mean * mean));
  };
  DrawSpec u{{"k"}, Distribution::kUniform, 2.0, 4.0};
  auto [um, us] = moments(u);
  EXPECT_NEAR(um, 3.0, 0.03 * 0.577);
  EXPECT_NEAR(us, 2.0 / std::sqrt(12.0), 0.02);
  DrawSpec g{{"k"}, Distribution::kNormal, 1.0, 0.5};
  auto [gm, gs] = moments(g);
  EXPECT_NEAR(gm, 1.0, 0.03 * 0.5);
  EXPECT_NEAR(gs, 0.5, 0.02 * 0.5);
  // Lognormal(mu, sigma): mean exp(mu + sigma^2/2).
  DrawSpec l{{"k"}, Distribution::kLognormal, 0.0, 0.25};
  auto [lm, ls] = moments(l);
  EXPECT_NEAR(lm, std::exp(0.25 * 0.25 / 2), 0.03 * 0.26);
  (void)ls;
  // Truncation: every draw inside [low, high].
  DrawSpec t{{"k"}, Distribution::kNormal, 0.0, 1.0, -0.5, 0.5};
  for (int j = 0; j < 2000; ++j) {
    const double x = draw_value(t, 1, j, 3);
    EXPECT_GE(x, -0.5);
    EXPECT_LE(x, 0.5);
  }
  // Pure: the same inputs give the same bits; another seed another number.
  EXPECT_EQ(draw_value(g, 5, 17, 2), draw_value(g, 5, 17, 2));
  EXPECT_NE(draw_value(g, 5, 17, 2), draw_value(g, 6, 17, 2));
}

TEST(StudyCases, ControllerKeepsTheNominalModelWhileThePlantVaries) {
  const Study s = families();
  const auto cases = expand(s);
  Resolver r(s);
  // Grid point 4 of the SMC: mass x1.2, Fs 150, Fc 110.
  const ResolvedCase c = r.resolve(cases[1 + 4]);
  sim::ResolvedKeys keys;
  const sim::Scenario sc = sim::parse_scenario(c.yaml, ".", "case", &keys);
  EXPECT_DOUBLE_EQ(sc.plant.mass, 102.04 * 1.2);
  EXPECT_DOUBLE_EQ(sc.plant.friction.static_force, 150);
  EXPECT_DOUBLE_EQ(sc.controller.sliding_mode.model.mass, 102.04);
  EXPECT_DOUBLE_EQ(sc.controller.sliding_mode.model.friction.static_force, 120);  // the scenario's nominal Fs
  EXPECT_EQ(c.parameters.at("plant.mass"), validate::format_number(102.04 * 1.2));
  // The cascade: its model mass too.
  const ResolvedCase k = r.resolve(cases[57 + 1 + 4]);
  const sim::Scenario kc = sim::parse_scenario(k.yaml, ".", "case");
  EXPECT_DOUBLE_EQ(kc.plant.mass, 102.04 * 1.2);
  EXPECT_DOUBLE_EQ(kc.controller.cascade.mass, 102.04);
  EXPECT_DOUBLE_EQ(kc.controller.cascade.kv, 3000);
  // The sensor follows: the controller is set up for the encoder it has.
  const ResolvedCase m = r.resolve(cases[7]);
  const sim::Scenario mc = sim::parse_scenario(m.yaml, ".", "case");
  EXPECT_DOUBLE_EQ(mc.plant.sensor.quantization, 5e-8);
  EXPECT_DOUBLE_EQ(mc.controller.sliding_mode.model.sensor.quantization, 5e-8);
  EXPECT_TRUE(mc.plant.effects.input_delay.enabled);
  EXPECT_FALSE(mc.controller.sliding_mode.model.effects.input_delay.enabled);
  EXPECT_DOUBLE_EQ(mc.controller.sliding_mode.model.friction.bristle_stiffness, 2e6);
  // The rows of cases without a variation carry the nominal value.
  EXPECT_EQ(r.resolve(cases[0]).parameters.at("plant.mass"), "102.04");
}

// A key in its old spelling (a renamed key's alias, docs/contributing.md) is the key: it scales
// its nominal value, its column carries the value, and the case's scenario warns of the spelling.
TEST(StudyCases, AnOldSpellingOfAKeyIsTheKey) {
  const Study s = parse_study(study_text(R"(
families:
  - name: grid
    set: {plant.effects.input_delay.delay_s: 1.0e-3}
    grid:
      - {key: plant.effects.input_delay.delay_s, scale: [0.5, 2]}
)"),
                              ".", "s.yaml");
  const auto cases = expand(s);
  ASSERT_EQ(cases.size(), 2u);
  Resolver r(s);
  const ResolvedCase c = r.resolve(cases[1]);
  EXPECT_DOUBLE_EQ(c.scenario->plant.effects.input_delay.delay, 2e-3);
  // results.csv's column is the key's canonical spelling, so an old and a new spelling of one
  // key in two families are one column (varied_keys).
  EXPECT_EQ(c.parameters.at("plant.effects.input_delay.delay"), "0.002");
  EXPECT_EQ(c.parameters.count("plant.effects.input_delay.delay_s"), 0u);
  EXPECT_NE(c.yaml.find("delay: 0.002"), std::string::npos) << c.yaml;  // the case is written in the new key
  EXPECT_EQ(std::count(c.scenario->warnings.begin(), c.scenario->warnings.end(),
                       "plant.effects.input_delay.delay_s: old spelling of plant.effects.input_delay.delay "
                       "(deprecated: rename the key)"),
            1);
}

TEST(StudyCases, AnOldAndANewSpellingAreOneColumn) {
  const Study s = parse_study(study_text(R"(
families:
  - name: old
    grid:
      - {key: plant.effects.input_delay.delay_s, values: [1.0e-3, 2.0e-3]}
  - name: new
    grid:
      - {key: plant.effects.input_delay.delay, values: [3.0e-3]}
)"),
                              ".", "s.yaml");
  EXPECT_EQ(varied_keys(s), std::vector<std::string>{"plant.effects.input_delay.delay"});
  const auto cases = expand(s);
  ASSERT_EQ(cases.size(), 3u);
  Resolver r(s);
  EXPECT_EQ(r.resolve(cases[0]).parameters.at("plant.effects.input_delay.delay"), "0.001");
  EXPECT_EQ(r.resolve(cases[2]).parameters.at("plant.effects.input_delay.delay"), "0.003");
}

TEST(StudyCases, FollowsPlantRuleLetsTheModelFollow) {
  Study s = families();
  s.model = ModelRule::kFollowsPlant;
  Resolver r(s);
  const sim::Scenario sc = sim::parse_scenario(r.resolve(expand(s)[1 + 4]).yaml, ".", "case");
  EXPECT_DOUBLE_EQ(sc.controller.sliding_mode.model.mass, 102.04 * 1.2);
}

TEST(StudyCases, HashesAreDistinctStableAndFollowTheScenario) {
  const Study s = families();
  const auto cases = expand(s);
  Resolver r(s), again(s);
  std::set<std::string> hashes;
  for (const CaseSpec& c : cases) {
    const ResolvedCase a = r.resolve(c);
    EXPECT_EQ(a.hash, again.resolve(c).hash);
    EXPECT_EQ(a.hash, sha256_hex(std::string(kCaseFormat) + a.yaml));
    hashes.insert(a.hash);
  }
  EXPECT_EQ(hashes.size(), cases.size());
  // A changed base value changes every hash.
  Study t = s;
  t.set.push_back({"plant.friction.viscous", "1.5"});
  Resolver rt(t);
  EXPECT_NE(rt.resolve(cases[0]).hash, r.resolve(cases[0]).hash);
}

TEST(StudyCases, Sha256KnownAnswers) {
  // FIPS 180-2 test vectors.
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

TEST(StudyCases, WrongKeysAndValuesAreTheLoadersOneLineErrors) {
  const auto error_of = [](const std::string& rest) {
    const Study s = parse_study(study_text(rest), ".", "s.yaml");
    Resolver r(s);
    try {
      for (const CaseSpec& c : expand(s)) r.resolve(c);
    } catch (const StudyError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
      return m;
    }
    ADD_FAILURE() << rest;
    return std::string();
  };
  const std::string mc_delay =
      "families:\n  - name: f\n    monte_carlo: {draws: 2, seed: 1, parameters: [{key: controller.computation_delay,"
      " distribution: uniform, low: 0.5, high: 2, scale: true}]}\n";
  const auto grid = [](const std::string& axis) { return "families:\n  - {name: f, grid: [" + axis + "]}\n"; };
  for (const auto& [rest, expected] : std::vector<std::pair<std::string, std::string>>{
           {grid("{key: plant.frction.static_force, values: [1]}"),
            "family 'f', point 0: plant.frction: unknown key (did you mean 'friction'?)"},
           {grid("{key: plant.mass, values: [-3]}"), "plant.mass = -3: must be > 0"},
           {grid("{key: plant.friction.model.x, values: [1]}"),
            "plant.friction.model is a single value in the scenario, not a map of keys"},
           {grid("{key: plant.friction.model, scale: [2]}"),
            "plant.friction.model = 'lugre': cannot scale a value that is not a number"},
           {grid("{key: reference.frequency, scale: [2]}"),
            "reference.frequency: cannot scale a key the scenario does not have"},
           // A factor on a zero (the default computation delay) would make every case the nominal one.
           {grid("{key: controller.computation_delay, scale: [2, 3]}"),
            "family 'f', point 0: controller.computation_delay = 0: scaling a zero value gives 0 for every factor"},
           {mc_delay, "controller.computation_delay = 0: scaling a zero value"},
           // What the struct cannot take is the case's one-line error naming the key and the value,
           // never a fallback to YAML (issue 22): a type switch that would leave the old type's keys,
           // a preset that is none, a null, a whole section.
           {"families:\n  - {name: f, set: {controller.type: cascade}}\n",
            "controller.type = cascade: controller.boundary_layer is given and is not a key of cascade"},
           {grid("{key: plant.ripple, values: [pape]}"),
            "family 'f', point 0: plant.ripple = pape: expected a map of keys, or one of none, paper"},
           {grid("{key: plant.mass, values: ['~']}"), "plant.mass = '~': not a number"},
           {"families:\n  - {name: f, set: {reference: '{type: step}'}}\n",
            "reference = {type: step}: a whole section is not set at once"}}) {
    EXPECT_NE(error_of(rest).find(expected), std::string::npos) << expected;
  }
}

TEST(StudyCases, EveryKindOfSettingBuildsTheCaseAsAStruct) {
  const Study s = parse_study(
      "name: t\nbase: {duration: 0.01, control_period: 1.0e-4, controller: {type: sliding_mode},"
      " reference: {type: step, amplitude: 1.0e-4}}\n"
      "families:\n  - name: f\n    grid:\n"
      "      - {key: controller.type, values: [sliding_mode, cascade]}\n"
      "      - {key: plant.ripple, values: [paper, none]}\n"
      "      - {key: plant.friction, values: ['{model: none}', '{model: static, coulomb_force: 70}']}\n",
      ".", "s.yaml");
  Resolver r(s);
  const auto cases = expand(s);
  ASSERT_EQ(cases.size(), 8u);
  for (const CaseSpec& c : cases) {
    const ResolvedCase rc = r.resolve(c);
    ASSERT_TRUE(rc.scenario);
    sim::ResolvedKeys keys;
    sim::parse_scenario(rc.yaml, ".", "case", &keys);
    EXPECT_EQ(sim::resolved_keys(*rc.scenario), keys) << r.label(c);
  }
  EXPECT_TRUE(r.resolve(cases[0]).scenario->plant.ripple.enabled);  // the paper's ripple
  const ResolvedCase last = r.resolve(cases.back());                // cascade, no ripple, static friction
  const sim::Scenario& sc = *last.scenario;
  EXPECT_EQ(sc.controller.type, sim::ControllerType::kCascade);
  EXPECT_FALSE(sc.plant.ripple.enabled);
  EXPECT_EQ(sc.plant.friction.model, plant::FrictionModel::kStatic);
  EXPECT_DOUBLE_EQ(sc.plant.friction.coulomb_force, 70);
  EXPECT_DOUBLE_EQ(sc.plant.friction.static_force, 120);  // the default: the map replaced the part
  EXPECT_EQ(sc.controller.model.friction.model, plant::FrictionModel::kLuGre);  // the nominal model rule
  // Built on another MPI rank from the case's settings (cases.hpp): the same struct, which runs
  // to the same metrics, bit for bit.
  CaseBuilder rank(unpack_bases(pack_bases(StudyBases::of(s))));
  const auto there = rank.build(unpack_settings(pack_settings(last.settings)), "case");
  ASSERT_TRUE(same_case(sc, *there));
  const Outcome a = run_case(sc), b = run_case(*there);
  ASSERT_TRUE(a.ok) << a.error;
  ASSERT_TRUE(b.ok) << b.error;
  ASSERT_EQ(a.metrics.size(), b.metrics.size());
  for (std::size_t i = 0; i < a.metrics.size(); ++i) {
    EXPECT_EQ(a.metrics[i].first, b.metrics[i].first);
    EXPECT_TRUE(a.metrics[i].second == b.metrics[i].second ||
                (std::isnan(a.metrics[i].second) && std::isnan(b.metrics[i].second)))
        << a.metrics[i].first;
  }
  EXPECT_EQ(a.warnings, b.warnings);
}

// An MPI rank builds each case from the study's bases (sent once) and the case's settings (sent
// with it), never from a YAML document of the case: every case of a study with two controllers, a
// grid of absolute and scaled values, Monte Carlo draws, a family set and the nominal model rule
// is the same struct on the rank as on rank 0 (same_case: every section's list by fields::same,
// the resolved keys, the reader's records beside the lists). The resolved YAML read back, what
// ranks parsed before, is not the same struct: every key counts as given there.
TEST(StudyCases, ACaseBuiltOnAnotherRankIsTheSameStruct) {
  const Study s = families();
  Resolver local(s);
  const std::string bases = pack_bases(StudyBases::of(s));  // what rank 0 sends each rank once
  CaseBuilder rank(unpack_bases(bases));
  std::size_t n = 0;
  for (std::size_t i = 0; i < case_count(s); i += 3) {  // every third case: 38 of 114, each family and controller
    const CaseSpec c = case_at(s, i);
    const ResolvedCase here = local.resolve(c);
    const std::string sent = pack_settings(here.settings);  // what rank 0 sends with the case
    const CaseSettings received = unpack_settings(sent);
    EXPECT_TRUE(received == here.settings) << local.label(c);
    const auto there = rank.build(received, "case " + std::to_string(i));
    EXPECT_TRUE(same_case(*here.scenario, *there)) << local.label(c);
    EXPECT_TRUE(fields::same(here.scenario->plant, there->plant)) << local.label(c);
    EXPECT_TRUE(fields::same(here.scenario->controller.sliding_mode.model, there->controller.sliding_mode.model))
        << local.label(c);
    ++n;
  }
  EXPECT_EQ(n, 38u);
  // The check can fail: the resolved YAML read back (the old wire format) gives another struct.
  const ResolvedCase first = local.resolve(case_at(s, 0));
  EXPECT_FALSE(same_case(*first.scenario, sim::parse_scenario(first.yaml, ".", "case")));
  // And the nominal model rule is in the settings: a plant-only variation with it.
  const ResolvedCase grid = local.resolve(case_at(s, 1 + 4));
  EXPECT_TRUE(grid.settings.nominal_model);
  EXPECT_DOUBLE_EQ(rank.build(grid.settings, "case")->controller.sliding_mode.model.mass, 102.04);
}

// The packings: what one packs the other unpacks; bytes that are not a packing are one line.
TEST(StudyCases, SettingsAndBasesPackAndUnpack) {
  CaseSettings c;
  c.controller = 3;
  c.nominal_model = true;
  c.layers = {{"duration", "0.5"}, {"plant.friction", "{model: static, coulomb_force: 70}"}};
  c.values = {{"plant.mass", "97.5"}, {"name", "with:colons\nand a newline"}, {"x", ""}};
  EXPECT_TRUE(unpack_settings(pack_settings(c)) == c);
  const StudyBases b{"s.yaml", "duration: 1\n", "/tmp", {"a", "b:c"}, {"", "{type: cascade}"}};
  EXPECT_TRUE(unpack_bases(pack_bases(b)) == b);
  for (const std::string& bad : {std::string(""), std::string("1:3"), std::string("x:"), pack_settings(c) + "1:a",
                                 pack_settings(c).substr(0, 20), std::string("99999999999999:")}) {
    try {
      unpack_settings(bad);
      ADD_FAILURE() << "unpacked: " << bad;
    } catch (const StudyError& e) {
      EXPECT_NE(std::string(e.what()).find("do not unpack"), std::string::npos) << e.what();
    }
  }
}

TEST(StudyCases, TheStudysSetHoldsForEveryControllerAndAControllersOwnSetIsMoreSpecific) {
  // Before: the controller block and its scenario's control_period replaced what the study's set
  // said, silently (a 1 ms delay in set: ran with none).
  const std::string t =
      "set: {duration: 0.02, control_period: 2.0e-4, controller.computation_delay: 1.0e-3, controller.lambda: 77}\n"
      "controllers:\n"
      "  - {name: sgn, scenario: " +
      test::scenarios() +
      "/smc_jerk_limited.yaml}\n"
      "  - {name: bl, controller: {type: sliding_mode, switching: sat, lambda: 1000},"
      " set: {controller.lambda: 500}}\n";
  const Study s = parse_study("name: t\nbase: " + test::scenarios() + "/smc_bl_jerk_limited.yaml\n" + t, ".", "s.yaml");
  Resolver r(s);
  const auto cases = expand(s);
  ASSERT_EQ(cases.size(), 2u);
  const sim::Scenario a = sim::parse_scenario(r.resolve(cases[0]).yaml, ".", "case");
  EXPECT_DOUBLE_EQ(a.control_period, 2e-4);  // not the 20 us of its scenario file
  EXPECT_DOUBLE_EQ(a.controller.computation_delay, 1e-3);
  EXPECT_DOUBLE_EQ(a.controller.sliding_mode.lambda, 77);
  const sim::Scenario b = sim::parse_scenario(r.resolve(cases[1]).yaml, ".", "case");
  EXPECT_DOUBLE_EQ(b.control_period, 2e-4);
  EXPECT_DOUBLE_EQ(b.controller.computation_delay, 1e-3);
  EXPECT_DOUBLE_EQ(b.controller.sliding_mode.lambda, 500);  // the controller's own set wins
  // A study-level set naming a key another controller type does not have is the loader's
  // one-line error, not dropped.
  const Study c =
      parse_study("name: t\nbase: " + test::scenarios() +
                      "/smc_bl_jerk_limited.yaml\n"
                      "set: {controller.lambda: 77}\ncontrollers:\n  - {name: c, controller: {type: cascade}}\n",
                  ".", "s.yaml");
  Resolver rc(c);
  try {
    rc.resolve(expand(c)[0]);
    ADD_FAILURE() << "controller.lambda on a cascade was accepted";
  } catch (const StudyError& e) {
    EXPECT_NE(std::string(e.what()).find("controller.lambda: unknown key"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace feeddrive::study
