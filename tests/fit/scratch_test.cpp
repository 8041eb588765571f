#include <gtest/gtest.h>
#include "feeddrive/fit/workflow.hpp"
#include "fit_util.hpp"
namespace feeddrive::fit {
TEST(Scratch, Null) {
  plant::PlantParams truth = test::base_model();
  if (std::getenv("NOFRIC")) truth.friction.model = plant::FrictionModel::kNone;
  if (std::getenv("STATIC")) truth.friction.model = plant::FrictionModel::kStatic;
  test::Recording ro; ro.seed = 11;
  for (int mode = 0; mode < 1; ++mode) {
    ro.quantization = mode == 1 ? 50e-9 : 0; ro.noise = mode == 1 ? 20e-9 : 0; ro.jitter = mode == 2 ? 0.005 : 0;
    const MeasuredData data = test::record(truth, ro, test::temp_dir());
    Record rec = prepare(data);
    mask_stiction(rec, truth);
    const auto rk = rank_candidates(rec, truth);
    std::printf("mode %d force rms %.4g active %ld of %zu\n", mode, rms(force_residual(rec, truth), rec.active_points()), rec.active_points(), rec.bank.tau.size());
    for (std::size_t i = 0; i < rk.size(); ++i) {
      std::printf("   [%.3f s, %ld ev]", rk[i].wall_time_s, rk[i].evaluations);
      std::printf("   %-20s %8.4g :", rk[i].effect.name.c_str(), rk[i].score);
      for (auto& [k, v] : rk[i].effect.parameters) std::printf(" %s=%.4g", k.c_str(), v);
      std::printf("\n");
    }
  }
}
}
