// Stationary points of the forced averaged equations (3.3) by Newton: residual at the solution,
// the linear case against a direct linear solve, hysteresis of a bistable (Duffing) sweep, and
// non-convergence reported instead of thrown.
#include "cvg_bench/core/model/stationary_solver.h"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include "cvg_bench/core/common/errors.h"
#include "paper_section4_estimate.h"

namespace cvg_bench {
namespace {

// The paper's section-4 cubic estimate (13 parameters, forced mode).
const ParameterValues& kPaper = testing_support::kSection4Estimate;
constexpr double kOmega = testing_support::kSection4OmegaRadS;

TEST(StationarySolver, SolvesPaperModelAcrossSweep) {
  const ResonatorModel model("xi", ExperimentMode::kForced);
  const Eigen::VectorXd z = model.parameterVector(kPaper);
  Eigen::Vector4d q = Eigen::Vector4d::Zero();
  for (double lambda = -150; lambda <= 150; lambda += 5) {
    const double rate = detuningRate(kOmega, kOmega + lambda);
    const StationaryPoint p = solveStationaryPoint(model, z, SlowContext{}, rate, q);
    ASSERT_TRUE(p.converged) << "lambda " << lambda << ": " << p.failure;
    EXPECT_LT(stationaryResidual(model, p.q, SlowContext{}, z, rate).norm(), 1e-10);
    EXPECT_LT(p.residual_norm, 1e-10);
    q = p.q;  // continuation
  }
}

TEST(StationarySolver, LinearModelEqualsDirectSolve) {
  // F is affine in q for the linear model: F(q) = F(0) + J q, so q* = -J^-1 F(0).
  const ResonatorModel model("linear", ExperimentMode::kForced);
  const Eigen::VectorXd z = model.parameterVector(kPaper);
  const double rate = detuningRate(kOmega, kOmega + 30.0);
  const Eigen::Vector4d f0 = stationaryResidual(model, Eigen::Vector4d::Zero(), {}, z, rate);
  const Eigen::Matrix4d j = stationaryJacobian(model, Eigen::Vector4d::Ones(), {}, z, rate);
  const Eigen::Vector4d expected = -j.fullPivLu().solve(f0);
  const StationaryPoint p =
      solveStationaryPoint(model, z, SlowContext{}, rate, Eigen::Vector4d(3, -2, 1, 1));
  ASSERT_TRUE(p.converged) << p.failure;
  EXPECT_LT((p.q - expected).norm(), 1e-10 * expected.norm());
}

TEST(StationarySolver, BistableDuffingSweepShowsHysteresis) {
  // One driven mode with strong cubic stiffness: up- and down-sweeps settle on different branches
  // inside the bistable band, and both are genuine stationary points.
  const ResonatorModel model("xi", ExperimentMode::kForced);
  const Eigen::VectorXd z = model.parameterVector({{"gamma", 2.0}, {"u2", 4.0}, {"xi", 40.0}});
  const double lambda_probe = -12.0;  // the response leans to lambda < 0 for xi > 0
  auto sweep = [&](double from, double to, double step) {
    Eigen::Vector4d q = Eigen::Vector4d::Zero();
    for (double l = from; step > 0 ? l <= to + 1e-9 : l >= to - 1e-9; l += step) {
      const StationaryPoint p =
          solveStationaryPoint(model, z, SlowContext{}, detuningRate(kOmega, kOmega + l), q);
      EXPECT_TRUE(p.converged) << "lambda " << l << ": " << p.failure;
      q = p.q;
    }
    return q;
  };
  const Eigen::Vector4d up = sweep(-30.0, lambda_probe, 0.5);
  const Eigen::Vector4d down = sweep(10.0, lambda_probe, -0.5);
  const double rate = detuningRate(kOmega, kOmega + lambda_probe);
  EXPECT_LT(stationaryResidual(model, up, {}, z, rate).norm(), 1e-10);
  EXPECT_LT(stationaryResidual(model, down, {}, z, rate).norm(), 1e-10);
  EXPECT_GT(down.norm(), 1.5 * up.norm())
      << "up " << up.transpose() << " down " << down.transpose();
}

TEST(StationarySolver, NonConvergenceIsReportedNotThrown) {
  const ResonatorModel model("xi", ExperimentMode::kForced);
  const Eigen::VectorXd z = model.parameterVector(kPaper);
  StationarySolverOptions options;
  options.max_iterations = 1;
  const StationaryPoint p =
      solveStationaryPoint(model, z, SlowContext{}, 10.0, Eigen::Vector4d(50, 50, 50, 50), options);
  EXPECT_FALSE(p.converged);
  EXPECT_FALSE(p.failure.empty());
  EXPECT_TRUE(p.q.allFinite());
}

TEST(StationarySolver, RejectsInvalidOptionsAndInputs) {
  StationarySolverOptions bad;
  bad.max_iterations = 0;
  bad.step_tolerance = 2.0;
  EXPECT_EQ(bad.validate().size(), 2u);
  const ResonatorModel model("linear", ExperimentMode::kForced);
  const Eigen::VectorXd z = model.parameterVector(kPaper);
  EXPECT_THROW(solveStationaryPoint(model, z, {}, 1.0, Eigen::Vector4d::Zero(), bad), InputError);
  EXPECT_THROW(solveStationaryPoint(model, z, {}, NAN, Eigen::Vector4d::Zero()), InputError);
}

}  // namespace
}  // namespace cvg_bench
