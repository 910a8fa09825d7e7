// Known-answer tests of the ring-down interval machinery
// (estimate/uncertainty/ar_noise_covariance.h): the exact AR whitening of the explain criterion and
// the block check's coverage under noise whose correlation changes along the record.
#include "cvg_bench/core/estimate/uncertainty/ar_noise_covariance.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "cvg_bench/core/estimate/uncertainty/student_t.h"

namespace cvg_bench {
namespace {

TEST(RingdownIntervals, ArWhiteningKeepsTheFirstSamples) {
  const std::vector<double> e = {1.0, 2.0, -1.0, 0.5};
  // AR(1), a = 0.8: the first sample scaled by sqrt(1 - a^2), then e_i - a e_{i-1}.
  const std::vector<double> w1 = arWhiten({0.8}, e);
  ASSERT_EQ(w1.size(), e.size());
  EXPECT_NEAR(w1[0], 0.6, 1e-9);
  EXPECT_NEAR(w1[1], 2.0 - 0.8, 1e-9);
  EXPECT_NEAR(w1[3], 0.5 + 0.8, 1e-9);
  // AR(2), a = (0.5, 0.2): rho1 = a1 / (1 - a2) = 0.625, rho2 = a1 rho1 + a2 = 0.5125, innovation
  // variance / gamma_0 = 1 - a1 rho1 - a2 rho2 = 0.585; sample 1 predicted by rho1 e_0 with
  // variance 1 - rho1^2.
  const std::vector<double> w2 = arWhiten({0.5, 0.2}, e);
  EXPECT_NEAR(w2[0], std::sqrt(0.585), 1e-6);
  EXPECT_NEAR(w2[1], (2.0 - 0.625) * std::sqrt(0.585 / (1.0 - 0.625 * 0.625)), 1e-6);
  EXPECT_NEAR(w2[2], -1.0 - 0.5 * 2.0 - 0.2 * 1.0, 1e-9);
  // A simulated stationary AR(2) series whitens to its innovations' variance.
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  const int n = 20000;
  std::vector<double> x(n);
  double x1 = 0.0, x2 = 0.0;
  for (int i = -500; i < n; ++i) {
    const double v = 0.5 * x1 + 0.2 * x2 + g(rng);
    x2 = x1, x1 = v;
    if (i >= 0) x[i] = v;
  }
  double s = 0.0;
  for (double v : arWhiten({0.5, 0.2}, x)) s += v * v;
  EXPECT_NEAR(s / n, 1.0, 0.04);
}

// Residual noise of a straight-line fit: white at the start, then a strongly filtered component
// ten times larger (relative noise early in a ring-down, the lock-in-filtered floor late).
Eigen::VectorXd changingNoise(std::mt19937& rng, int n) {
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::VectorXd e(n);
  double s1 = 0.0, s2 = 0.0;
  const double a = 0.95;
  for (int i = -300; i < n; ++i) {
    const double w = g(rng);
    s1 = a * s1 + (1 - a) * w;
    s2 = a * s2 + (1 - a) * s1;
    if (i >= 0) e(i) = 0.3 * g(rng) + (i > n / 2 ? 60.0 * s2 : 0.0);
  }
  return e;
}

TEST(RingdownIntervals, BlockCheckKeepsCoverageWhenTheCorrelationChanges) {
  std::mt19937 rng(7);
  const int n = 800, reps = 300;
  Eigen::MatrixXd J(n, 2);
  for (int i = 0; i < n; ++i) J(i, 0) = 1.0, J(i, 1) = static_cast<double>(i) / n;
  int covered = 0, covered_model = 0;
  for (int r = 0; r < reps; ++r) {
    const Eigen::VectorXd e = changingNoise(rng, n);  // truth: slope 0
    const Eigen::VectorXd b = J.colPivHouseholderQr().solve(e);
    const Eigen::VectorXd res = e - J * b;
    const ArNoiseCovariance c = arNoiseCovariance(J, res);
    const ArNoiseCovariance m = arNoiseCovariance(J, res, false);
    const double z = studentQuantile(0.95, std::max(1, static_cast<int>(c.student_df)));
    const double zm = studentQuantile(0.95, std::max(1, static_cast<int>(m.student_df)));
    covered += std::fabs(b(1)) <= z * std::sqrt(c.covariance(1, 1));
    covered_model += std::fabs(b(1)) <= zm * std::sqrt(m.covariance(1, 1));
    EXPECT_GE(c.covariance(1, 1), m.covariance(1, 1) * (1 - 1e-12));
  }
  // 95 % intervals: the block check holds 0.90 .. 0.99 (binomial sd 0.013 at 300 replications).
  EXPECT_GE(covered, static_cast<int>(0.90 * reps)) << "AR-model-only coverage " << covered_model;
  EXPECT_LE(covered, static_cast<int>(0.99 * reps)) << "AR-model-only coverage " << covered_model;
}

// A step inside a block makes a least-squares AR fit explosive; the covariance stays finite.
TEST(RingdownIntervals, LocalArCovarianceIsFiniteWithAStepInABlock) {
  const int n = 1600;
  Eigen::MatrixXd J(n, 2);
  Eigen::VectorXd r(n);
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 0.01);
  for (int i = 0; i < n; ++i) {
    J(i, 0) = 1.0, J(i, 1) = static_cast<double>(i) / n;
    r(i) = (i > 1000 ? 1.0 : 0.0) + (i > 1000 ? 2e-3 * (i - 1000) : 0.0) + g(rng);
  }
  const ArNoiseCovariance c = arNoiseCovarianceLocal(J, r, 4);
  EXPECT_TRUE(c.covariance.allFinite());
  EXPECT_GT(c.covariance(1, 1), 0.0);
}

// The options' defaults are the values the covariance always used: passing them explicitly gives
// the same numbers bit for bit, and a stricter detection band turns the AR model off.
TEST(RingdownIntervals, DefaultOptionsEqualTheImplicitOnes) {
  std::mt19937 rng(11);
  const int n = 800;
  Eigen::MatrixXd J(n, 2);
  for (int i = 0; i < n; ++i) J(i, 0) = 1.0, J(i, 1) = static_cast<double>(i) / n;
  const Eigen::VectorXd e = changingNoise(rng, n);
  const Eigen::VectorXd res = e - J * J.colPivHouseholderQr().solve(e);
  const ArNoiseOptions o;
  const ArNoiseCovariance a = arNoiseCovariance(J, res), b = arNoiseCovariance(J, res, true, o);
  EXPECT_TRUE(a.covariance == b.covariance);
  EXPECT_EQ(a.method, b.method);
  EXPECT_EQ(a.ljung_box_p, b.ljung_box_p);
  const ArNoiseCovariance la = arNoiseCovarianceLocal(J, res, 4);
  const ArNoiseCovariance lb = arNoiseCovarianceLocal(J, res, 4, o);
  EXPECT_TRUE(la.covariance == lb.covariance);
  EXPECT_EQ(la.method, lb.method);
  ASSERT_TRUE(a.correlated);
  ArNoiseOptions never;
  never.lag1_band_z = 1e300;
  never.ljung_box_level = 0.0;
  const ArNoiseCovariance w = arNoiseCovariance(J, res, false, never);
  EXPECT_FALSE(w.correlated);
  EXPECT_TRUE(w.covariance == w.crb);
}

}  // namespace
}  // namespace cvg_bench
