// Block RLS (2.12) with the corrected pairing reproduces the batch estimate (forgetting 1).
#include "cvg_bench/core/estimate/recursive_least_squares.h"

#include <gtest/gtest.h>

#include <random>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/identification.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "identification_test_support.h"

namespace cvg_bench {
namespace {

TEST(BlockRls, EqualsBatchOnTheSameData) {
  const ResonatorModel model("xi+kappa", ExperimentMode::kFreeDecay);
  const ParameterValues truth = {{"gamma", 0.05}, {"nu", 0.02},   {"b_c", 0.01}, {"b_s", -0.008},
                                 {"c_m", 0.3},    {"n", 0.05},    {"h_c", 0.1},  {"h_s", -0.07},
                                 {"xi", 0.2},     {"kappa", 0.05}};
  const SlowRecord rec = testing_support::withNoise(
      testing_support::simulateFreeDecay(model, model.parameterVector(truth),
                                         slowFromOrbit({1.0, 0.1, 0.3, 0.0}), 0.02, 2000),
      1e-3, 11);
  IdentificationOptions opt;
  opt.model = "xi+kappa";
  const Estimate batch = identifyFreeDecay(rec, opt);
  opt.method = "rls";
  const Estimate rls = identifyFreeDecay(rec, opt);
  ASSERT_EQ(rls.method, "rls");
  for (int j = 0; j < batch.values.size(); ++j)
    EXPECT_NEAR(rls.values[j], batch.values[j], 1e-8 * std::fabs(batch.values[j]))
        << batch.names[j];
  EXPECT_NEAR(rls.sigma, batch.sigma, 1e-8 * batch.sigma);
}

TEST(BlockRls, RunningResidualAndCovarianceMatchBatch) {
  std::mt19937_64 gen(5);
  std::normal_distribution<double> n01;
  const int k = 5, blocks = 60, m = 10;
  Eigen::MatrixXd a(4 * blocks, k);
  Eigen::VectorXd y(4 * blocks);
  for (int i = 0; i < a.rows(); ++i) {
    for (int j = 0; j < k; ++j) a(i, j) = n01(gen);
    y[i] = n01(gen);
  }
  IncrementalQr init(k);
  init.addRows(a.topRows(4 * m), y.head(4 * m));
  BlockRecursiveLeastSquares rls(k);
  rls.initialize(init.rAug(), init.numRows());
  for (int b = m; b < blocks; ++b) rls.update(a.middleRows(4 * b, 4), y.segment<4>(4 * b));
  const LeastSquaresSolution ls = solveLeastSquares(a, y, 1e-12);
  EXPECT_LT((Eigen::VectorXd(rls.z()) - ls.z).norm(), 1e-12 * ls.z.norm());
  EXPECT_NEAR(rls.rss(), ls.rss, 1e-10 * ls.rss);
  EXPECT_LT((Eigen::MatrixXd(rls.p()) - ls.unscaled_covariance).norm(),
            1e-10 * ls.unscaled_covariance.norm());
  EXPECT_EQ(rls.numEquations(), 4 * blocks);
  EXPECT_GT(rls.predictionSigmaBound(1.0), 1.0);
}

TEST(BlockRls, RankDeficientStartAndBadOptionsAreErrors) {
  BlockRecursiveLeastSquares rls(3);
  IncrementalQr qr(3);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(8, 3);
  a.col(0).setOnes();
  qr.addRows(a, Eigen::VectorXd::Ones(8));
  EXPECT_THROW(rls.initialize(qr.rAug(), 8), AnalysisError);
  EXPECT_THROW(BlockRecursiveLeastSquares(3, 0.0), InputError);
  EXPECT_THROW(rls.update(RegressionBlockMatrix::Zero(4, 3), Eigen::Vector4d::Zero()),
               AnalysisError);
}

}  // namespace
}  // namespace cvg_bench
