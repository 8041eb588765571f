// The translators between the message contract and the domain structs (record/translate.hpp,
// service/translate.hpp), and their messages over memq:// through service::Bus, as the nodes
// send and receive them. Every field gets a value of its own, so a field copied into another's
// place shows. Values out of the contract's bounds: cut by the sender where the contract says
// so (run_info_t.scenario), else dropped and counted by the receiver (reference_block_t.count).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <optional>
#include <string>

#include "feeddrive/common/fields.hpp"
#include "feeddrive/control_command_t.hpp"
#include "feeddrive/reference_block_t.hpp"
#include "feeddrive/run_info_t.hpp"
#include "feeddrive/service/contract.hpp"
#include "feeddrive/service/translate.hpp"
#include "feeddrive/wire.hpp"
#include "protocol_util.hpp"

namespace feeddrive::protocol_test {
namespace {

using namespace service;

/// Publishes `m` on a memq:// bus and returns what its subscriber decoded (waits at most 5 s).
template <typename Msg>
std::optional<Msg> over_memq(const Msg& m) {
  Memq memq;
  auto bus = peer(memq);
  std::optional<Msg> got;
  bus->subscribe<Msg>("T", [&](const Msg& r, std::int64_t) { got = r; });
  bus->publish("T", m);
  poll_until(*bus, [&] { return got.has_value(); });
  return got;
}

TEST(Translate, AReferenceRoundTripsOverMemq) {
  const trajectory::Sample s{0.125, -0.25, 3.5, -40.0};
  reference_block_t b{};
  b.first_seq = 12;
  b.count = 1;
  b.refs = {to_message(12, 0.0012, s)};
  const auto block = over_memq(b);
  ASSERT_TRUE(block) << "not received within 5 s";
  EXPECT_EQ(block->run_id, kRunId) << "stamped by the bus";
  ASSERT_EQ(block->refs.size(), 1u);
  const reference_t* got = &block->refs[0];
  EXPECT_EQ(got->seq, 12);
  EXPECT_EQ(got->t, 0.0012);
  const trajectory::Sample back = to_sample(*got);
  EXPECT_EQ(back.position, s.position);
  EXPECT_EQ(back.velocity, s.velocity);
  EXPECT_EQ(back.acceleration, s.acceleration);
  EXPECT_EQ(back.jerk, s.jerk);
}

TEST(Translate, ACommandRoundTripsOverMemq) {
  controller::Command c;
  c.u = 1.5;
  c.u_unsaturated = 2.5;
  c.sliding = -3e-4;
  c.z_estimate = 1e-7;
  const auto got = over_memq(to_message(7, 0.0007, c));
  ASSERT_TRUE(got) << "not received within 5 s";
  EXPECT_EQ(got->seq, 7);
  EXPECT_EQ(got->t, 0.0007);
  EXPECT_EQ(got->u, 1.5);
  EXPECT_EQ(got->u_unsaturated, 2.5);
  EXPECT_EQ(got->sliding, -3e-4);
  EXPECT_EQ(got->z_estimate, 1e-7);
}

TEST(Translate, StateTruthAndMeasurement) {
  const plant::State st{0.01, 0.2, 3e-6, 40.0, 1.5};
  drive_state_t m{};
  m.t = 0.0042;
  m.x_measured = 0.0101;
  m.v_measured = 0.199;
  m.truth = to_truth_message(st);
  m.previous = no_applied();
  const auto got = over_memq(m);
  ASSERT_TRUE(got) << "not received within 5 s";
  EXPECT_TRUE(got->truth.valid);
  EXPECT_EQ(got->truth.x, 0.01);
  EXPECT_EQ(got->truth.v, 0.2);
  EXPECT_EQ(got->truth.z, 3e-6);
  EXPECT_EQ(got->truth.fg, 40.0);
  EXPECT_EQ(got->truth.i, 1.5);
  const controller::Truth t = to_truth(got->truth);  // what a controller may use of it
  EXPECT_EQ(t.z, 3e-6);
  EXPECT_EQ(t.fg, 40.0);
  const plant::Measurement meas = to_measurement(*got);
  EXPECT_EQ(meas.t, 0.0042);
  EXPECT_EQ(meas.x, 0.0101);
  EXPECT_EQ(meas.v, 0.199);
}

TEST(Translate, AppliedAndNothingApplied) {
  const plant::Forces f{10.0, -2.0, 0.5, -7.0, 0.0};
  const applied_t a = to_applied(3, 0.75, f);
  EXPECT_EQ(a.seq, 3);
  EXPECT_EQ(a.u, 0.75);
  EXPECT_TRUE(a.forces_valid);
  EXPECT_EQ(a.f_thrust, 10.0);
  EXPECT_EQ(a.f_friction, -2.0);
  EXPECT_EQ(a.f_ripple, 0.5);
  EXPECT_EQ(a.f_grinding, -7.0);
  const applied_t none = no_applied();  // state 0: nothing applied before it
  EXPECT_EQ(none.seq, -1);
  EXPECT_FALSE(none.forces_valid);
  EXPECT_TRUE(std::isnan(none.u));
  EXPECT_TRUE(std::isnan(none.f_thrust) && std::isnan(none.f_friction) && std::isnan(none.f_ripple) &&
              std::isnan(none.f_grinding));
}

// A row of timeseries.csv from step k's messages: the truth and the forces only when the
// messages carry them (hardware: NaN, never a made-up 0).
TEST(Translate, ARowFromTheMessagesOfAStep) {
  drive_state_t st{};
  st.t = 0.003;
  st.x_measured = 0.02;
  st.v_measured = 0.1;
  st.truth = to_truth_message(plant::State{0.021, 0.11, 1e-6, 5.0, 0.3});
  const reference_t ref = to_message(30, 0.003, trajectory::Sample{0.022, 0.12, 1.0, 2.0});
  controller::Command c;
  c.u = 0.9;
  c.u_unsaturated = 1.9;
  c.sliding = 0.01;
  c.z_estimate = 2e-6;
  const control_command_t cmd = to_message(30, 0.003, c);
  const applied_t applied = to_applied(30, 0.8, plant::Forces{20.0, -3.0, 0.25, -1.0, 0.0});
  const sim::Record r = to_record(st, ref, cmd, applied);
  EXPECT_EQ(r.t, 0.003);
  EXPECT_EQ(r.xd, 0.022);
  EXPECT_EQ(r.vd, 0.12);
  EXPECT_EQ(r.x, 0.021);
  EXPECT_EQ(r.fg, 5.0);
  EXPECT_EQ(r.x_measured, 0.02);
  EXPECT_EQ(r.u, 0.8) << "u is what the plant applied (state k+1), not the command";
  EXPECT_EQ(r.u_unsaturated, 1.9);
  EXPECT_EQ(r.sliding, 0.01);
  EXPECT_EQ(r.f_thrust, 20.0);
  EXPECT_EQ(r.f_friction, -3.0);

  st.truth.valid = false;
  const sim::Record hw = to_record(st, ref, cmd, no_applied());
  EXPECT_TRUE(std::isnan(hw.x) && std::isnan(hw.v) && std::isnan(hw.z) && std::isnan(hw.fg) && std::isnan(hw.i));
  EXPECT_TRUE(std::isnan(hw.f_thrust) && std::isnan(hw.f_friction));
  EXPECT_EQ(hw.x_measured, 0.02) << "the measurement is there either way";
}

// run_info_t: the scenario and the options, the command limits of the scenario's controller
// type, "auto" sensor velocity resolved as the plant resolves it; a scenario name beyond the
// contract's 255 bytes is cut by the sender, so that the message still decodes everywhere.
TEST(Translate, RunInfoFromTheScenarioAndOptions) {
  sim::Scenario s = scenario(20);
  NodeOptions opt = node_options();
  opt.step_timeout_s = 2.5;
  opt.monitor_window = 64;
  const run_info_t i = to_run_info(s, opt, "abc123");
  EXPECT_EQ(i.scenario, "protocol");
  EXPECT_EQ(i.mode, "lockstep");
  EXPECT_EQ(i.steps, 20);
  EXPECT_EQ(i.control_period, 1e-4);
  EXPECT_EQ(i.step_timeout, 2.5);
  EXPECT_EQ(i.monitor_window, 64);
  EXPECT_EQ(i.scenario_hash, "abc123");
  EXPECT_EQ(i.contract_version, kContractVersion);
  EXPECT_EQ(i.current_step, -1);
  EXPECT_EQ(i.plant_count, static_cast<std::int16_t>(i.plant.size()));
  EXPECT_EQ(i.u_min, s.controller.sliding_mode.u_min);
  EXPECT_EQ(i.u_max, s.controller.sliding_mode.u_max);
  EXPECT_EQ(i.sensor_velocity, s.plant.sensor.ideal() ? "true" : "difference");

  s.controller.type = sim::ControllerType::kCascade;
  s.controller.cascade.u_min = -3.25;
  s.controller.cascade.u_max = 4.5;
  opt.realtime = true;
  const run_info_t c = to_run_info(s, opt, "");
  EXPECT_EQ(c.u_min, -3.25);
  EXPECT_EQ(c.u_max, 4.5);
  EXPECT_EQ(c.mode, "realtime");

  s.name = std::string(300, 'n');
  const auto got = over_memq(to_run_info(s, opt, ""));
  ASSERT_TRUE(got) << "a run_info_t with a 300-byte scenario name did not arrive";
  EXPECT_EQ(got->scenario, std::string(wire::Check<run_info_t>::kMax_scenario, 'n'));
}

// The value of run_info_t.plant's entry `key`, or nullptr.
const parameter_t* entry(const run_info_t& i, const std::string& key) {
  for (const parameter_t& p : i.plant)
    if (p.key == key) return &p;
  return nullptr;
}

// run_info_t.plant is the plant's one list walked (plant::parameter_table): every key of
// PlantParams' Serialize, walked here independently, arrives over memq:// with the scenario's
// value, bit for bit, except the effects (the hidden discrepancy) and the integrator; a key added
// to the list reaches the participants without a change here. Contract 3 had a hand-written set
// of fields that missed friction.stribeck_exponent (the C++ example assumed delta = 2).
TEST(Translate, RunInfoCarriesEveryParameterOfThePlantList) {
  sim::Scenario s = scenario(20);
  s.plant.friction.stribeck_exponent = 1.7;
  s.plant.friction.static_smoothing_shape = 0.5;
  s.plant.ripple.cogging_third = 0.75;
  s.plant.effects.constant_force.enabled = true;
  s.plant.effects.constant_force.force = 3.0;
  const auto got = over_memq(to_run_info(s, node_options(), ""));
  ASSERT_TRUE(got) << "run_info_t did not arrive";
  std::size_t listed = 0;
  for (const fields::FlatValue& v : fields::flatten(s.plant)) {
    const parameter_t* p = entry(*got, v.key);
    if (v.key.rfind("effects.", 0) == 0 || v.key.rfind("integrator.", 0) == 0) {
      EXPECT_EQ(p, nullptr) << v.key << " is not told to the participants";
      continue;
    }
    ++listed;
    ASSERT_NE(p, nullptr) << v.key << " is missing from run_info_t.plant";
    EXPECT_EQ(p->name, v.name) << v.key;
    if (v.is_name) {
      EXPECT_TRUE(std::isnan(p->value)) << v.key;
    } else {
      EXPECT_EQ(std::memcmp(&p->value, &v.number, sizeof(double)), 0) << v.key << " = " << p->value;
    }
  }
  EXPECT_EQ(got->plant.size(), listed + 2) << "the list and the two derived values";
  ASSERT_NE(entry(*got, "friction.stribeck_exponent"), nullptr);
  EXPECT_EQ(entry(*got, "friction.stribeck_exponent")->value, 1.7);
  EXPECT_EQ(entry(*got, "friction.static_smoothing_shape")->value, 0.5);
  EXPECT_EQ(entry(*got, "friction.model")->name, "lugre");
  EXPECT_EQ(entry(*got, "thrust_gain")->value, s.plant.thrust_gain());
  EXPECT_EQ(entry(*got, "grinding.damping")->value, s.plant.grinding.damping());
  EXPECT_EQ(entry(*got, "input_limit")->value, s.plant.input_limit);
  EXPECT_EQ(got->plant_count, static_cast<std::int16_t>(got->plant.size()));
}

// A table that does not fit the contract's bounds is refused, never cut: a key cut to 47 bytes
// would name another parameter.
TEST(Translate, AParameterBeyondTheContractsBoundsIsRefused) {
  std::vector<fields::FlatValue> t = {{"mass", 1.0, "", false}};
  EXPECT_EQ(to_parameters(t).size(), 1u);
  t.push_back({std::string(wire::Check<parameter_t>::kMax_key + 1, 'k'), 2.0, "", false});
  EXPECT_THROW(to_parameters(t), std::logic_error);
  std::vector<fields::FlatValue> many(static_cast<std::size_t>(wire::Check<run_info_t>::kMax_plant_count) + 1,
                                      {"mass", 1.0, "", false});
  EXPECT_THROW(to_parameters(many), std::logic_error);
}

// A block of no references (the contract: 1..16) leaves the sender but no receiver takes it:
// dropped before the handler, counted as invalid on its channel, the reason naming the field.
TEST(Translate, AReferenceBlockBeyondItsBoundIsDroppedAndCounted) {
  Memq memq;
  auto bus = peer(memq);
  int delivered = 0;
  bus->subscribe<reference_block_t>("T", [&](const reference_block_t&, std::int64_t) { ++delivered; });
  reference_block_t b{};
  b.first_seq = 0;
  b.count = 0;
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(b.getEncodedSize()));
  ASSERT_EQ(b.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  reference_block_t out;
  std::string why;
  EXPECT_FALSE(wire::decode_untrusted(bytes.data(), bytes.size(), out, &why));
  EXPECT_NE(why.find("reference_block_t.count = 0"), std::string::npos) << why;
  bus->publish("T", b);
  b.count = 1;
  b.refs = {to_message(0, 0.0, trajectory::Sample{})};
  bus->publish("T", b);  // within the bound: delivered
  EXPECT_TRUE(poll_until(*bus, [&] { return delivered == 1 && bus->invalid() == 1; }))
      << delivered << " delivered, " << bus->invalid() << " invalid";
  EXPECT_EQ(bus->invalid_by_channel().at("T"), 1);
}

}  // namespace
}  // namespace feeddrive::protocol_test
