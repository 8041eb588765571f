// Speed of the in-process simulation (Google Benchmark).
//
//   BM_ControlPeriodFullModel: one control period of the full model at defaults (LuGre + ripple +
//     grinding, 10 kHz, sliding-mode controller): measure, control, CVODE advance with restart.
//     items_per_second = control periods per second (target >= 100,000 on one core).
//   BM_ControlPeriodJerkLimitedMove: the same on the 0.2 m/s jerk-limited move.
//   BM_JerkLimitedRun/...: whole jerk-limited runs (records included); counter sim_s_per_wall_s.
//
// Run: ./build/bin/bench_feeddrive --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <optional>
#include <vector>

#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/plant/plant.hpp"
#include "feeddrive/service/integrity.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/simulation.hpp"

namespace {

using namespace feeddrive;

std::string scenario_path(const char* name) { return std::string(FEEDDRIVE_SOURCE_DIR) + "/scenarios/" + name; }

// One control period (reference, measurement, controller, CVODE advance with restart), cycling
// through the scenario's run so every phase is sampled. The plant and controller are rebuilt
// (untimed) at the end of each run.
void control_periods(benchmark::State& state, const sim::Scenario& s) {
  std::optional<plant::Plant> drive;
  drive.emplace(s.plant, s.control_period);
  auto reference = sim::make_reference(s);
  auto controller = sim::make_controller(s);
  long k = 0;
  const long steps = s.steps();
  for (auto _ : state) {
    if (k == steps) {
      state.PauseTiming();
      drive.emplace(s.plant, s.control_period);
      controller = sim::make_controller(s);
      k = 0;
      state.ResumeTiming();
    }
    const double t = s.time_of(k);
    const auto ref = reference->sample(t);
    const auto meas = drive->measure();
    const auto st = drive->state();
    const controller::Truth truth{st.z, st.fg};
    const auto cmd = controller->update(ref, meas, &truth);
    drive->advance(cmd.u, s.time_of(k + 1));
    benchmark::DoNotOptimize(cmd.u);
    ++k;
  }
  state.SetItemsProcessed(state.iterations());
}

// The full model at defaults: LuGre + ripple + Hahn-Lindsay grinding, 10 kHz, the sliding-mode
// controller, default integrator tolerances, on the paper's grinding infeed (Fig. 23 ramp).
// items_per_second = control periods per second (target >= 100,000 on one core).
void BM_ControlPeriodFullModel(benchmark::State& state) {
  control_periods(state, sim::load_scenario(scenario_path("paper/smc_bl_ramp_all_forces.yaml")));
}
BENCHMARK(BM_ControlPeriodFullModel)->MinTime(2.0);

// The same, on the 0.2 m/s jerk-limited move with LuGre + ripple (grinding off: a rapid move
// is not in contact), where friction's bristle dynamics are fastest.
void BM_ControlPeriodJerkLimitedMove(benchmark::State& state) {
  sim::Scenario s = sim::load_scenario(scenario_path("paper/smc_bl_jerk_limited.yaml"));
  s.plant.ripple = plant::RippleParams::paper();
  s.controller.sliding_mode.model = s.plant;
  control_periods(state, s);
}
BENCHMARK(BM_ControlPeriodJerkLimitedMove)->MinTime(2.0);

void jerk_limited_run(benchmark::State& state, const char* file) {
  const sim::Scenario s = sim::load_scenario(scenario_path(file));
  double sim_s = 0.0;
  for (auto _ : state) {
    const auto r = sim::run(s);
    benchmark::DoNotOptimize(r.records.data());
    sim_s += s.duration;
  }
  state.counters["sim_s_per_wall_s"] = benchmark::Counter(sim_s, benchmark::Counter::kIsRate);
  state.counters["periods"] = static_cast<double>(s.steps());
}
// The paper's configuration: hard sgn at 20 us (75,000 periods for 1.5 s).
void BM_JerkLimitedRun_PaperHardSgn20us(benchmark::State& state) {
  jerk_limited_run(state, "paper/smc_jerk_limited.yaml");
}
BENCHMARK(BM_JerkLimitedRun_PaperHardSgn20us)->Unit(benchmark::kMillisecond)->MinTime(2.0);
// The beyond-the-paper configuration at 10 kHz (observers, 50 nm encoder).
void BM_JerkLimitedRun_Beyond10kHz(benchmark::State& state) {
  jerk_limited_run(state, "paper/beyond_jerk_limited.yaml");
}
BENCHMARK(BM_JerkLimitedRun_Beyond10kHz)->Unit(benchmark::kMillisecond)->MinTime(2.0);

}  // namespace

// Authentication of the bus (--key, docs/security.md): one HMAC-SHA256 to sign a drive_state_t
// (the largest message of a step) and one to verify it, as Bus::publish and subscribe do.
static std::vector<std::uint8_t> encoded_state() {
  drive_state_t m{};
  const int n = m.getEncodedSize();
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(n) + feeddrive::service::MessageAuth::kMacSize);
  m.encode(buf.data(), 0, n);
  return buf;
}
static void BM_SignDriveState(benchmark::State& state) {
  const feeddrive::service::MessageAuth auth("0123456789abcdef0123456789abcdef");
  std::vector<std::uint8_t> buf = encoded_state();
  for (auto _ : state) {
    auth.sign("FD_STATE", buf.data(), buf.size());
    benchmark::DoNotOptimize(buf.data());
  }
  state.counters["bytes"] = static_cast<double>(buf.size());
}
BENCHMARK(BM_SignDriveState)->MinTime(1.0);
static void BM_VerifyDriveState(benchmark::State& state) {
  const feeddrive::service::MessageAuth auth("0123456789abcdef0123456789abcdef");
  std::vector<std::uint8_t> buf = encoded_state();
  auth.sign("FD_STATE", buf.data(), buf.size());
  for (auto _ : state) benchmark::DoNotOptimize(auth.verify("FD_STATE", buf.data(), buf.size()));
}
BENCHMARK(BM_VerifyDriveState)->MinTime(1.0);

BENCHMARK_MAIN();
