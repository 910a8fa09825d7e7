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

/// Residuals and Jacobian blocks (row-major, as Ceres writes them) of a cost at (x_z, x_q).
struct Evaluated {
  std::vector<double> r, jz, jq;
};
Evaluated evaluate(const ceres::CostFunction& cost, const Eigen::VectorXd& xz,
                   const Eigen::Vector4d& xq) {
  Evaluated e;
  e.r.resize(cost.num_residuals());
  e.jz.resize(cost.num_residuals() * xz.size());
  e.jq.resize(cost.num_residuals() * 4);
  const double* params[] = {xz.data(), xq.data()};
  double* jac[] = {e.jz.data(), e.jq.data()};
  EXPECT_TRUE(cost.Evaluate(params, e.r.data(), jac));
  return e;
}

double maxAbsDiff(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0.0;
  for (size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

// The forward-sensitivity Jacobian is the exact derivative of the RK4 map: it equals Ridders'
// extrapolated numeric derivative (accurate to ~1e-12 relative) on a nonlinear model with a
// time-dependent term, scaled unknowns and substeps; the residuals are the functor's.
TEST(OutputErrorFreeDecay, SensitivityJacobianEqualsRiddersDifferences) {
  const ResonatorModel model("xi+kappa+gamma_nl+cm_rate", ExperimentMode::kFreeDecay);
  const Eigen::VectorXd z = model.parameterVector({{"gamma", 0.5},
                                                   {"nu", 0.3},
                                                   {"b_c", 0.05},
                                                   {"b_s", -0.04},
                                                   {"c_m", 0.4},
                                                   {"n", 0.1},
                                                   {"h_c", 0.3},
                                                   {"h_s", -0.2},
                                                   {"xi", 0.6},
                                                   {"kappa", 0.2},
                                                   {"gamma_nl", 0.1},
                                                   {"cm_rate", 0.05}});
  SlowRecord record;
  record.t_s = timeGrid(61, 0.05);
  const Eigen::Vector4d q0(0.8, 0.3, -0.2, 0.4);
  ASSERT_TRUE(integrateSlowTrajectory(model, z * 1.1, q0, record.t_s, 2, &record.q));
  const Eigen::VectorXd z_scale = Eigen::VectorXd::LinSpaced(z.size(), 0.5, 2.0);
  const double q0_scale = 0.7;
  const auto exact = makeFreeDecayOutputErrorCost(
      model, record, 2, TrajectoryDerivative::kSensitivity, z_scale, q0_scale);
  const auto ridders = makeFreeDecayOutputErrorCost(
      model, record, 2, TrajectoryDerivative::kRidders, z_scale, q0_scale);
  const Eigen::VectorXd xz = z.cwiseQuotient(z_scale);
  const Eigen::Vector4d xq = q0 / q0_scale;
  const Evaluated a = evaluate(*exact, xz, xq);
  const Evaluated b = evaluate(*ridders, xz, xq);
  EXPECT_LT(maxAbsDiff(a.r, b.r), 1e-15);
  double scale = 0.0;
  for (double v : b.jz) scale = std::max(scale, std::abs(v));
  EXPECT_GT(scale, 1e-2);
  EXPECT_LT(maxAbsDiff(a.jz, b.jz), 1e-9 * scale);
  EXPECT_LT(maxAbsDiff(a.jq, b.jq), 1e-9);
}

/// A nonlinear record with a time-dependent term for the square-root and dense evaluators.
struct NonlinearCase {
  ResonatorModel model{"xi+cm_rate", ExperimentMode::kFreeDecay};
  Eigen::VectorXd z, z_scale;
  Eigen::Vector4d q0{0.8, 0.3, -0.2, 0.4};
  double q0_scale = 0.7;
  SlowRecord record;
  NonlinearCase() {
    z = model.parameterVector({{"gamma", 0.5},
                               {"nu", 0.3},
                               {"c_m", 0.4},
                               {"h_c", 0.3},
                               {"h_s", -0.2},
                               {"xi", 0.6},
                               {"cm_rate", 0.05}});
    record.t_s = timeGrid(301, 0.02);
    EXPECT_TRUE(integrateSlowTrajectory(model, z * 1.05, q0, record.t_s, 2, &record.q));
    z_scale = Eigen::VectorXd::LinSpaced(z.size(), 0.5, 2.0);
  }
};

// The square-root form [c; rho], [R; 0] carries what Levenberg-Marquardt uses from the full
// problem: the same cost, gradient J'r and Gauss-Newton matrix J'J (here 1204 residuals -> 12).
TEST(OutputErrorFreeDecay, SquareRootFormHasTheSameCostGradientAndGaussNewtonMatrix) {
  const NonlinearCase c;
  const auto full = makeFreeDecayOutputErrorCost(
      c.model, c.record, 2, TrajectoryDerivative::kSensitivity, c.z_scale, c.q0_scale);
  const auto root = makeFreeDecaySquareRootCost(c.model, c.record, 2, c.z_scale, c.q0_scale);
  const int p = c.model.numParameters(), m = p + 4;
  ASSERT_EQ(root->num_residuals(), m + 1);
  const Eigen::VectorXd xz = c.z.cwiseQuotient(c.z_scale);
  const Eigen::Vector4d xq = c.q0 / c.q0_scale;
  const Evaluated a = evaluate(*full, xz, xq);
  const Evaluated b = evaluate(*root, xz, xq);
  auto stacked = [&](const Evaluated& e, int rows) {
    Eigen::MatrixXd j(rows, m);
    for (int r = 0; r < rows; ++r) {
      for (int k = 0; k < p; ++k) j(r, k) = e.jz[r * p + k];
      for (int k = 0; k < 4; ++k) j(r, p + k) = e.jq[r * 4 + k];
    }
    return j;
  };
  const int n = full->num_residuals();
  const Eigen::MatrixXd ja = stacked(a, n), jb = stacked(b, m + 1);
  const Eigen::Map<const Eigen::VectorXd> ra(a.r.data(), n), rb(b.r.data(), m + 1);
  EXPECT_GT(ra.norm(), 1e-3);
  EXPECT_NEAR(rb.squaredNorm(), ra.squaredNorm(), 1e-12 * ra.squaredNorm());
  const Eigen::VectorXd ga = ja.transpose() * ra, gb = jb.transpose() * rb;
  EXPECT_LT((ga - gb).norm(), 1e-10 * ga.norm());
  const Eigen::MatrixXd ha = ja.transpose() * ja, hb = jb.transpose() * jb;
  EXPECT_LT((ha - hb).norm(), 1e-12 * ha.norm());
  // Cost-only evaluation: the same squared norm.
  std::vector<double> r(m + 1);
  const double* params[] = {xz.data(), xq.data()};
  ASSERT_TRUE(root->Evaluate(params, r.data(), nullptr));
  EXPECT_NEAR(Eigen::Map<Eigen::VectorXd>(r.data(), m + 1).squaredNorm(), ra.squaredNorm(),
              1e-12 * ra.squaredNorm());
}

// The dense evaluator writes the sensitivity cost's rows in the unscaled unknowns, and the
// initial-state sensitivity is the last 4 columns of the full one.
TEST(OutputErrorFreeDecay, DenseEvaluatorAndInitialSensitivityMatchTheCost) {
  const NonlinearCase c;
  const auto full = makeFreeDecayOutputErrorCost(
      c.model, c.record, 2, TrajectoryDerivative::kSensitivity, c.z_scale, c.q0_scale);
  const Evaluated a = evaluate(*full, c.z.cwiseQuotient(c.z_scale), c.q0 / c.q0_scale);
  Eigen::MatrixXd j;
  Eigen::VectorXd r;
  ASSERT_TRUE(evaluateFreeDecayOutputError(c.model, c.record, 2, c.z, c.q0, &j, &r));
  const int p = c.model.numParameters();
  ASSERT_EQ(j.rows(), full->num_residuals());
  ASSERT_EQ(j.cols(), p + 4);
  double worst = 0.0;
  for (int row = 0; row < j.rows(); ++row) {
    worst = std::max(worst, std::abs(r[row] - a.r[row]));
    for (int k = 0; k < p; ++k)
      worst = std::max(worst, std::abs(j(row, k) * c.z_scale[k] - a.jz[row * p + k]));
    for (int k = 0; k < 4; ++k)
      worst = std::max(worst, std::abs(j(row, p + k) * c.q0_scale - a.jq[row * 4 + k]));
  }
  EXPECT_LT(worst, 1e-13);
  double worst_s = 0.0;
  ASSERT_TRUE(integrateSlowInitialSensitivity(
      c.model, c.z, c.q0, c.record.t_s, 2,
      [&](size_t i, const Eigen::Vector4d& q, const Eigen::Matrix4d& s) {
        worst_s = std::max(worst_s, (q - c.record.q[i] - r.segment<4>(4 * i)).norm());
        worst_s = std::max(worst_s, (s - j.block(4 * i, p, 4, 4)).norm());
      }));
  EXPECT_LT(worst_s, 1e-13);
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
