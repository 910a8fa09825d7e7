// The streaming QR solver against a dense reference, and its rank decisions.
#include "cvg_bench/core/estimate/least_squares_solver.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <Eigen/QR>
#include <random>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/uncertainty/student_t.h"

namespace cvg_bench {
namespace {

TEST(LeastSquares, StreamingQrMatchesDenseQr) {
  std::mt19937_64 gen(1);
  std::normal_distribution<double> n01;
  Eigen::MatrixXd a(1003, 7);
  Eigen::VectorXd y(1003);
  for (int i = 0; i < a.rows(); ++i) {
    for (int j = 0; j < a.cols(); ++j)
      a(i, j) = n01(gen) * std::pow(10.0, j - 3);  // scales 1e-3..1e3
    y[i] = n01(gen);
  }
  const LeastSquaresSolution s = solveLeastSquares(a, y, 1e-10);
  const Eigen::VectorXd ref = a.colPivHouseholderQr().solve(y);
  EXPECT_EQ(s.rank, 7);
  EXPECT_LT((s.z - ref).norm(), 1e-10 * ref.norm());
  EXPECT_NEAR(s.rss, (y - a * ref).squaredNorm(), 1e-9 * s.rss);
  const Eigen::MatrixXd cov =
      (a.transpose() * a).inverse();  // reference only, small and well posed
  EXPECT_LT((s.unscaled_covariance - cov).norm(), 1e-8 * cov.norm());
  EXPECT_EQ(s.null_space.cols(), 0);
}

TEST(LeastSquares, DependentColumnsGiveRankAndNullSpace) {
  std::mt19937_64 gen(2);
  std::normal_distribution<double> n01;
  Eigen::MatrixXd a(50, 4);
  for (int i = 0; i < a.rows(); ++i)
    for (int j = 0; j < 3; ++j) a(i, j) = n01(gen);
  a.col(3) = 2.0 * a.col(0) - a.col(1);
  const LeastSquaresSolution s = solveLeastSquares(a, a.col(2), 1e-9);
  EXPECT_EQ(s.rank, 3);
  ASSERT_EQ(s.null_space.cols(), 1);
  const Eigen::Vector4d expected = Eigen::Vector4d(2, -1, 0, -1).normalized();
  EXPECT_NEAR(std::fabs(s.null_space.col(0).dot(expected)), 1.0, 1e-9);
  EXPECT_NEAR(s.z[2], 1.0, 1e-9);
  EXPECT_THROW(solveLeastSquares(a, a.col(2), 0.0), InputError);
}

// The panel-blocked kernel for every model size (panels of 4 with tails of 1..3 columns), rows
// arriving as 4-row blocks and as odd-sized row batches (zero-row padding), several buffer flushes:
// R_aug' R_aug must equal [A y]'[A y] and R_aug must be upper triangular.
TEST(LeastSquares, StreamingFactorReproducesTheGramMatrixForEveryModelSize) {
  std::mt19937_64 gen(3);
  std::normal_distribution<double> n01;
  for (int k = 1; k <= kMaxModelParameters; ++k) {
    const int rows = 4 * 150 + 7;
    Eigen::MatrixXd a(rows, k);
    Eigen::VectorXd y(rows);
    for (int i = 0; i < rows; ++i) {
      for (int j = 0; j < k; ++j) a(i, j) = n01(gen) * std::pow(2.0, j % 5);
      y[i] = n01(gen);
    }
    if (k > 2) a.col(1).head(300).setZero();  // a column empty in the first flushes
    IncrementalQr qr(k);
    int i = 0;
    for (; i + 4 <= 4 * 150; i += 4) {
      const RegressionBlockMatrix d = a.middleRows(i, 4);
      qr.addBlock(d, y.segment<4>(i));
    }
    qr.addRows(a.bottomRows(rows - i), y.tail(rows - i));
    EXPECT_EQ(qr.numRows(), rows);
    Eigen::MatrixXd ay(rows, k + 1);
    ay << a, y;
    const Eigen::MatrixXd gram = ay.transpose() * ay;
    const Eigen::MatrixXd r = qr.rAug();
    EXPECT_LT((r.transpose() * r - gram).norm(), 1e-12 * gram.norm()) << "k = " << k;
    EXPECT_EQ(r.triangularView<Eigen::StrictlyLower>().toDenseMatrix().norm(), 0.0) << "k = " << k;
  }
}

TEST(StudentT, QuantilesOfTheTables) {
  EXPECT_NEAR(studentQuantile(0.95, 10), 2.228139, 1e-6);
  EXPECT_NEAR(studentQuantile(0.95, 0), 1.959964, 1e-6);
  EXPECT_NEAR(studentQuantile(0.99, 30), 2.749996, 1e-6);
  EXPECT_THROW(studentQuantile(1.0, 5), InputError);
}

}  // namespace
}  // namespace cvg_bench
