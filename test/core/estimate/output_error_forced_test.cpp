// Output-error residual of one forced sweep point: zero at the truth, and the analytic
// implicit-function Jacobians (z and mu blocks) against central differences of the residual.
#include "cvg_bench/core/estimate/output_error_forced.h"

#include <gtest/gtest.h>

#include "paper_section4_estimate.h"

namespace cvg_bench {
namespace {

const ParameterValues& kTruth = testing_support::kSection4Estimate;
constexpr double kOmega = testing_support::kSection4OmegaRadS;
constexpr double kMu = 0.2;

class OutputErrorForcedTest : public ::testing::Test {
 protected:
  OutputErrorForcedTest() : model_("xi+mu", ExperimentMode::kForced) {
    z_ = model_.parameterVector(kTruth);
    rate_ = detuningRate(kOmega, kOmega + 20.0);
    const StationaryPoint p =
        solveStationaryPoint(model_, z_, SlowContext{0.0, kMu}, rate_, Eigen::Vector4d::Zero());
    EXPECT_TRUE(p.converged) << p.failure;
    q_true_ = p.q;
  }
  ResonatorModel model_;
  Eigen::VectorXd z_;
  double rate_ = 0.0;
  Eigen::Vector4d q_true_;
};

TEST_F(OutputErrorForcedTest, ResidualVanishesAtTruth) {
  const ForcedPointOutputError cost(model_, rate_, q_true_, true, 0.0, {});
  double mu = kMu;
  const double* params[] = {z_.data(), &mu};
  Eigen::Vector4d r;
  ASSERT_TRUE(cost.Evaluate(params, r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-12);
}

TEST_F(OutputErrorForcedTest, AnalyticJacobiansMatchCentralDifferences) {
  const Eigen::Vector4d measured = q_true_ + Eigen::Vector4d(0.01, -0.02, 0.005, 0.01);
  const ForcedPointOutputError cost(model_, rate_, measured, true, 0.0, {});
  const int k = model_.numParameters();
  Eigen::VectorXd z = z_;
  double mu = kMu;
  const double* params[] = {z.data(), &mu};
  Eigen::Vector4d r;
  Eigen::Matrix<double, 4, Eigen::Dynamic, Eigen::RowMajor> jz(4, k);
  Eigen::Vector4d jmu;
  double* jac[] = {jz.data(), jmu.data()};
  ASSERT_TRUE(cost.Evaluate(params, r.data(), jac));
  auto residual = [&](const Eigen::VectorXd& zz, double m) {
    const double* p[] = {zz.data(), &m};
    Eigen::Vector4d out;
    EXPECT_TRUE(cost.Evaluate(p, out.data(), nullptr));
    return out;
  };
  for (int c = 0; c < k; ++c) {
    const double h = 1e-5 * std::max(1.0, std::abs(z[c]));
    Eigen::VectorXd zp = z, zm = z;
    zp[c] += h;
    zm[c] -= h;
    const Eigen::Vector4d numeric = (residual(zp, mu) - residual(zm, mu)) / (2 * h);
    EXPECT_LT((jz.col(c) - numeric).norm(), 1e-6 * (1 + numeric.norm()))
        << model_.parameterNames()[c];
  }
  const double h = 1e-6;
  const Eigen::Vector4d numeric_mu = (residual(z, mu + h) - residual(z, mu - h)) / (2 * h);
  EXPECT_LT((jmu - numeric_mu).norm(), 1e-6 * (1 + numeric_mu.norm()));
  EXPECT_GT(jmu.norm(), 1e-3);  // mu is visible in the data
}

TEST_F(OutputErrorForcedTest, KnownMuUsesOneParameterBlock) {
  const ForcedPointOutputError cost(model_, rate_, q_true_, false, kMu, {});
  ASSERT_EQ(cost.parameter_block_sizes().size(), 1u);
  const double* params[] = {z_.data()};
  Eigen::Vector4d r;
  ASSERT_TRUE(cost.Evaluate(params, r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-12);
}

}  // namespace
}  // namespace cvg_bench
