// Single-mode closed forms (q1 = q2 = p2 = 0 unless stated) that the averaged model must reproduce.
#include <gtest/gtest.h>

#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {
namespace {

TEST(SingleModeClosedForm, CubicGivesMinusThreeQuartersXiP1Cubed) {
  ResonatorModel m("xi", ExperimentMode::kFreeDecay);
  ParameterValues v{{"xi", 2.5}};
  const double p1 = 0.7;
  const Eigen::Vector4d rate = m.slowDerivative({0, p1, 0, 0}, {}, m.parameterVector(v));
  EXPECT_NEAR(2 * rate[0], -0.75 * 2.5 * p1 * p1 * p1, 1e-14);
  EXPECT_NEAR(rate[1], 0.0, 1e-14);
  EXPECT_NEAR(rate[2], 0.0, 1e-14);
  EXPECT_NEAR(rate[3], 0.0, 1e-14);
}

TEST(SingleModeClosedForm, QuinticGivesMinusFiveEighthsKappaP1ToTheFifth) {
  ResonatorModel m("kappa", ExperimentMode::kFreeDecay);
  const double p1 = 0.9, kappa = -1.7;
  const Eigen::Vector4d rate =
      m.slowDerivative({0, p1, 0, 0}, {}, m.parameterVector({{"kappa", kappa}}));
  EXPECT_NEAR(2 * rate[0], -0.625 * kappa * std::pow(p1, 5), 1e-14);
  EXPECT_NEAR(rate[1], 0.0, 1e-14);
}

TEST(SingleModeClosedForm, DampingDecaysAtHalfGamma) {
  ResonatorModel m("linear", ExperimentMode::kFreeDecay);
  const Eigen::Vector4d q(0.3, -0.4, 0, 0);
  const Eigen::Vector4d rate = m.slowDerivative(q, {}, m.parameterVector({{"gamma", 4.0}}));
  EXPECT_NEAR(rate[0], -2.0 * 0.3, 1e-14);
  EXPECT_NEAR(rate[1], -2.0 * -0.4, 1e-14);
}

// Forced mode (3.2): at the stationary point of an undamped-but-gamma, single-mode drive u~2 at
// zero detuning, 0 = -gamma p1 + u~2, so p1 = u~2 / gamma; the detuning term enters as
// -2 lambda p1 in 2 q1' and +2 lambda q1 in 2 p1'.
TEST(SingleModeClosedForm, ForcedSignsOfDriveAndDetuning) {
  ResonatorModel m("linear", ExperimentMode::kForced);
  const Eigen::VectorXd z = m.parameterVector({{"gamma", 2.0}, {"u2", 3.0}});
  const Eigen::Vector4d at_rest = m.slowDerivative({0, 1.5, 0, 0}, {}, z, 0.0);
  EXPECT_NEAR(at_rest.norm(), 0.0, 1e-14);
  const double d = 0.8;
  const Eigen::Vector4d q(0.2, 0.5, 0, 0);
  const Eigen::Vector4d with = m.slowDerivative(q, {}, z, d);
  const Eigen::Vector4d without = m.slowDerivative(q, {}, z, 0.0);
  EXPECT_NEAR(2 * (with[0] - without[0]), -d * q[1], 1e-14);
  EXPECT_NEAR(2 * (with[1] - without[1]), d * q[0], 1e-14);
  // drive u~1 pushes q1, u~3 pushes q2
  const Eigen::VectorXd z1 = m.parameterVector({{"u1", 1.0}, {"u3", 2.0}});
  const Eigen::Vector4d r1 = m.slowDerivative(Eigen::Vector4d::Zero(), {}, z1, 0.0);
  EXPECT_NEAR(2 * r1[0], 1.0, 1e-14);
  EXPECT_NEAR(2 * r1[2], 2.0, 1e-14);
}

TEST(SingleModeClosedForm, ExactDetuningRate) {
  const double w = 1000.0, lambda = 7.0;
  EXPECT_NEAR(detuningRate(w, w + lambda), 2 * lambda - lambda * lambda / (w + lambda), 1e-12);
}

}  // namespace
}  // namespace cvg_bench
