// fitted_residual_ar1.h: the expectation E[r'Lr] / E[r'r] computed from one backward recursion
// over J equals the sum of its lag products written out (the header's formula), and the corrected
// rho recovers an AR(1) coefficient that the fit's residuals understate.
#include "cvg_bench/core/estimate/uncertainty/fitted_residual_ar1.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

namespace cvg_bench {
namespace {

// The header's formula with every lag product M_d = sum_i J_{i+cd}' J_i formed explicitly.
double expectationByLagProducts(const Eigen::MatrixXd& j, const Eigen::MatrixXd& c, int channels,
                                double rho, int lags) {
  const long n = j.rows();
  const long p = j.cols();
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(p, p), x = Eigen::MatrixXd::Zero(p, p);
  Eigen::MatrixXd m1 = Eigen::MatrixXd::Zero(p, p);
  for (int d = 0; d <= lags && channels * d < n; ++d) {
    const long rows = n - channels * d;
    const Eigen::MatrixXd m = j.bottomRows(rows).transpose() * j.topRows(rows);
    if (d == 0) {
      s += m;
      x += rho * m.transpose();
      continue;
    }
    if (d == 1) m1 = m;
    s += std::pow(rho, d) * (m + m.transpose());
    x += std::pow(rho, d - 1) * m + std::pow(rho, d + 1) * m.transpose();
  }
  const Eigen::MatrixXd a = 0.5 * (x + x.transpose());
  const Eigen::MatrixXd b = 0.5 * (m1 + m1.transpose());
  const double rr = static_cast<double>(n) - (c * s).trace();
  const double rlr =
      static_cast<double>(n - channels) * rho - 2.0 * (c * a).trace() + (b * c * s * c).trace();
  return rlr / rr;
}

Eigen::MatrixXd slowBasis(long steps, int channels) {
  // Decaying, oscillating columns per channel (like trajectory sensitivities), plus a constant.
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(steps * channels, 3 * channels);
  for (long t = 0; t < steps; ++t) {
    const double u = static_cast<double>(t) / steps;
    for (int ch = 0; ch < channels; ++ch) {
      j(t * channels + ch, 3 * ch) = 1.0;
      j(t * channels + ch, 3 * ch + 1) = std::exp(-2.0 * u) * std::cos(9.0 * u + ch);
      j(t * channels + ch, 3 * ch + 2) = u * std::exp(-u);
    }
  }
  return j;
}

TEST(FittedResidualAr1, RecursionEqualsTheLagProducts) {
  const int channels = 4;
  const Eigen::MatrixXd j = slowBasis(700, channels);
  const Eigen::MatrixXd c = (j.transpose() * j).completeOrthogonalDecomposition().pseudoInverse();
  // lagsFor: ceil(ln 1e-4 / ln rho) lags, at most steps / 4 = 175 (rho 0.97 needs 303: capped).
  for (double rho : {0.3, 0.8, 0.97}) {
    const int lags = std::min(175, static_cast<int>(std::ceil(std::log(1e-4) / std::log(rho))));
    const double want = expectationByLagProducts(j, c, channels, rho, lags);
    EXPECT_NEAR(expectedResidualLag1(j, c, channels, rho), want, 1e-12 * std::abs(want))
        << "rho " << rho;
    EXPECT_LT(want, rho);  // the fit removes slow noise: the residuals' lag-1 falls
  }
}

TEST(FittedResidualAr1, RecoversTheNoiseCoefficientFromFittedResiduals) {
  // One channel, AR(1) rho = 0.9 noise, 400 samples, a 6-column slow basis fitted by LS: the
  // residuals' lag-1 correlation is ~0.86 on average, the corrected value is near 0.9.
  const long n = 400;
  Eigen::MatrixXd j(n, 6);
  for (long t = 0; t < n; ++t)
    for (int k = 0; k < 6; ++k) j(t, k) = std::pow(static_cast<double>(t) / n, k);
  const Eigen::MatrixXd c = (j.transpose() * j).completeOrthogonalDecomposition().pseudoInverse();
  std::mt19937 gen(5);
  std::normal_distribution<double> g(0.0, 1.0);
  double observed = 0.0, corrected = 0.0;
  const int runs = 200;
  for (int run = 0; run < runs; ++run) {
    Eigen::VectorXd e(n);
    e[0] = g(gen) / std::sqrt(1.0 - 0.81);
    for (long t = 1; t < n; ++t) e[t] = 0.9 * e[t - 1] + g(gen);
    const Eigen::VectorXd r = e - j * (c * (j.transpose() * e));
    const double lag1 = r.tail(n - 1).dot(r.head(n - 1)) / r.squaredNorm();
    observed += lag1 / runs;
    corrected += fittedResidualAr1(j, c, 1, lag1) / runs;
  }
  EXPECT_LT(observed, 0.87) << corrected;
  EXPECT_NEAR(corrected, 0.9, 0.015) << observed;
}

}  // namespace
}  // namespace cvg_bench
