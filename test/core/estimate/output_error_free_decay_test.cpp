// Output-error residuals of a free-decay record: the RK4 trajectory against the closed-form decay
// of a pure damping model, zero residual at the truth, and overflow reported as a failed
// evaluation.
#include "cvg_bench/core/estimate/output_error_free_decay.h"

#include <gtest/gtest.h>

#include <cmath>

namespace cvg_bench {
namespace {

std::vector<double> timeGrid(int n, double dt) {
  std::vector<double> t(n);
  for (int i = 0; i < n; ++i) t[i] = 1.5 + i * dt;  // any origin: the model counts from t[0]
  return t;
}

TEST(OutputErrorFreeDecay, PureDampingDecaysExponentially) {
  // 2 q' = -gamma q for the linear model with only gamma: q(t) = q0 exp(-gamma (t - t0) / 2).
  const ResonatorModel model("linear", ExperimentMode::kFreeDecay);
  const double gamma = 0.8;
  const Eigen::VectorXd z = model.parameterVector({{"gamma", gamma}});
  const Eigen::Vector4d q0(0.8, 0.3, -0.2, 0.4);
  const auto t = timeGrid(201, 0.02);
  std::vector<Eigen::Vector4d> traj;
  ASSERT_TRUE(integrateSlowTrajectory(model, z, q0, t, 1, &traj));
  for (size_t i = 0; i < t.size(); ++i) {
    const Eigen::Vector4d expected = q0 * std::exp(-gamma * (t[i] - t[0]) / 2);
    EXPECT_LT((traj[i] - expected).norm(), 1e-10) << "sample " << i;
  }
}

TEST(OutputErrorFreeDecay, ResidualVanishesAtTruthAndSeesParameterChange) {
  const ResonatorModel model("xi", ExperimentMode::kFreeDecay);
  const Eigen::VectorXd z = model.parameterVector(
      {{"gamma", 0.5}, {"nu", 0.3}, {"c_m", 0.4}, {"h_c", 0.3}, {"h_s", -0.2}, {"xi", 0.6}});
  SlowRecord record;
  record.t_s = timeGrid(101, 0.02);
  const Eigen::Vector4d q0(0.8, 0.3, -0.2, 0.4);
  ASSERT_TRUE(integrateSlowTrajectory(model, z, q0, record.t_s, 1, &record.q));
  const FreeDecayOutputError functor(model, record, 1);
  std::vector<double> r(functor.numResiduals());
  Eigen::VectorXd zz = z;
  Eigen::Vector4d qq = q0;
  const double* params[] = {zz.data(), qq.data()};
  ASSERT_TRUE(functor(params, r.data()));
  EXPECT_LT(Eigen::Map<Eigen::VectorXd>(r.data(), r.size()).norm(), 1e-14);
  zz[model.indexOf("xi")] += 0.01;
  ASSERT_TRUE(functor(params, r.data()));
  EXPECT_GT(Eigen::Map<Eigen::VectorXd>(r.data(), r.size()).norm(), 1e-4);
}

TEST(OutputErrorFreeDecay, OverflowIsAFailedEvaluation) {
  const ResonatorModel model("linear", ExperimentMode::kFreeDecay);
  SlowRecord record;
  record.t_s = timeGrid(101, 0.1);
  record.q.assign(101, Eigen::Vector4d(1, 0, 0, 0));
  Eigen::VectorXd z = model.parameterVector({{"gamma", -1e5}});
  Eigen::Vector4d q0(1, 0, 0, 0);
  const FreeDecayOutputError functor(model, record, 1);
  std::vector<double> r(functor.numResiduals());
  const double* params[] = {z.data(), q0.data()};
  EXPECT_FALSE(functor(params, r.data()));
}

}  // namespace
}  // namespace cvg_bench
