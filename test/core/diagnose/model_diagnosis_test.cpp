// Known answers of the explain statistics: Wald test, F tail, delta BIC, runs test.
#include "cvg_bench/core/diagnose/model_diagnosis.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/diagnose/residual_signature.h"

namespace cvg_bench {
namespace {

Estimate twoParameterEstimate(double a, double b, double var_a, double var_b, int dof) {
  Estimate e;
  e.model = "test";
  e.names = {"a", "b"};
  e.values = Eigen::Vector2d(a, b);
  e.covariance = Eigen::Vector2d(var_a, var_b).asDiagonal();
  e.interval_dof = dof;
  return e;
}

TEST(WaldTest, SingleParameterIsSquaredZScoreAgainstChiSquare) {
  // z = 2 / 1 = 2: W = 4, p = P(chi2_1 > 4) = 2 (1 - Phi(2)) = 0.0455003.
  const auto e = twoParameterEstimate(0.5, 2.0, 0.04, 1.0, 0);
  const WaldTestResult w = waldTest(e, {"b"});
  EXPECT_EQ(w.df1, 1);
  EXPECT_NEAR(w.f_statistic, 4.0, 1e-12);
  EXPECT_NEAR(w.p_value, 0.0455003, 1e-6);
}

TEST(WaldTest, JointTestWithStudentDofUsesFDistribution) {
  // W = (1/0.25 + 4/1) = 8, F = 4 on (2, 10): p = (1 + 2 F / 10)^-5 = 1.8^-5 = 0.0529221.
  const auto e = twoParameterEstimate(0.5, 2.0, 0.25 * 0.25, 1.0, 10);
  const WaldTestResult w = waldTest(e, {"a", "b"});
  EXPECT_EQ(w.df1, 2);
  EXPECT_NEAR(w.f_statistic, (0.25 / 0.0625 + 4.0) / 2, 1e-12);
  EXPECT_NEAR(w.p_value, std::pow(1.0 + 2.0 * 4.0 / 10.0, -5.0), 1e-9);
}

TEST(WaldTest, UnknownParameterIsInputError) {
  const auto e = twoParameterEstimate(0.5, 2.0, 1.0, 1.0, 0);
  EXPECT_THROW(waldTest(e, {"xi"}), InputError);
}

TEST(DeltaBic, PenaltyAndFit) {
  EXPECT_NEAR(deltaBic(1.0, 1.0, 100, 1), std::log(100.0), 1e-12);
  EXPECT_NEAR(deltaBic(2.0, 1.0, 100, 1), 100 * std::log(0.5) + std::log(100.0), 1e-12);
}

TEST(RunsTest, AlternatingAndBlockSequences) {
  std::vector<double> alternating, blocks;
  for (int i = 0; i < 100; ++i) {
    alternating.push_back(i % 2 ? 1.0 : -1.0);
    blocks.push_back(i < 50 ? -1.0 : 1.0);
  }
  const RunsTestResult a = runsTest(alternating), b = runsTest(blocks);
  EXPECT_EQ(a.runs, 100);
  EXPECT_GT(a.p_value, 0.99);
  EXPECT_EQ(b.runs, 2);
  EXPECT_NEAR(b.expected, 51.0, 1e-12);
  EXPECT_LT(b.p_value, 1e-12);
}

TEST(RunsTest, WhiteNoiseRejectionRateMatchesLevel) {
  // Under independence P(p < 0.05) should be ~0.05: 400 sequences, binomial sd 0.011.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n01;
  int rejected = 0;
  for (int s = 0; s < 400; ++s) {
    std::vector<double> v(200);
    for (auto& x : v) x = n01(rng);
    rejected += runsTest(v).p_value < 0.05;
  }
  EXPECT_NEAR(rejected / 400.0, 0.05, 4 * 0.011);
}

}  // namespace
}  // namespace cvg_bench
