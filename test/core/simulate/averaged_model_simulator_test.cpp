// The averaged-model simulator against closed-form solutions of (2.5): pure damping decays as
// exp(-gamma t / 2), the c_m term rotates (q1, p1) at c~m / 2; and an hour-long HRG-like ring-down.
#include "cvg_bench/core/simulate/averaged_model_simulator.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {

TEST(AveragedModelSimulator, MatchesClosedFormDampingAndRotation) {
  const double gamma = 0.7, c_m = 3.0;
  const ResonatorModel model("linear", ExperimentMode::kFreeDecay);
  AveragedModelSimulator sim(model, model.parameterVector({{"gamma", gamma}, {"c_m", c_m}}));
  const Eigen::Vector4d q0(1.0, 0.0, 0.2, -0.1);
  sim.reset(q0, 0.0);
  SlowRecord rec;
  sim.sample(10.0, 101, rec);
  for (size_t k = 0; k < rec.size(); ++k) {
    const double t = rec.t_s[k], a = std::exp(-gamma * t / 2), ph = c_m * t / 2;
    // 2 q1' = -gamma q1 + c_m p1, 2 p1' = -gamma p1 - c_m q1 (the D_gamma columns of (2.6)).
    const Eigen::Vector4d exact(a * (q0[0] * std::cos(ph) + q0[1] * std::sin(ph)),
                                a * (q0[1] * std::cos(ph) - q0[0] * std::sin(ph)),
                                a * (q0[2] * std::cos(ph) + q0[3] * std::sin(ph)),
                                a * (q0[3] * std::cos(ph) - q0[2] * std::sin(ph)));
    ASSERT_LT((rec.q[k] - exact).cwiseAbs().maxCoeff(), 1e-9) << "t = " << t;
  }
}

TEST(AveragedModelSimulator, HourLongHighQRingDownIsCheapAndExact) {
  const double gamma = 6.2832e-3;  // Q = 5e6 at 5 kHz
  const ResonatorModel model("xi", ExperimentMode::kFreeDecay);
  AveragedModelSimulator sim(model, model.parameterVector({{"gamma", gamma}, {"xi", 2e-3}}));
  sim.reset(Eigen::Vector4d(1.0, 0.0, 0.0, 0.0), 0.0);
  sim.advanceTo(3600.0);
  // The cubic term only rotates the phase of a single mode: the amplitude decays exactly.
  EXPECT_NEAR(sim.state().norm(), std::exp(-gamma * 3600.0 / 2), 1e-9);
  EXPECT_LT(sim.stepsTaken(), 20000);
}

TEST(AveragedModelSimulator, RejectsBadOptionsAndStates) {
  const ResonatorModel model("linear", ExperimentMode::kFreeDecay);
  AveragedModelSimulatorOptions o;
  o.relative_tolerance = 0.0;
  o.max_step_s = -1.0;
  EXPECT_EQ(o.validate().size(), 2u);
  EXPECT_THROW(AveragedModelSimulator(model, Eigen::VectorXd::Zero(8), 0.0, 0.0, o), InputError);
  AveragedModelSimulator sim(model, Eigen::VectorXd::Zero(8));
  EXPECT_THROW(sim.reset(Eigen::Vector4d::Constant(INFINITY)), InputError);
  sim.reset(Eigen::Vector4d::Zero(), 1.0);
  EXPECT_THROW(sim.advanceTo(0.0), InputError);
}

}  // namespace
}  // namespace cvg_bench
