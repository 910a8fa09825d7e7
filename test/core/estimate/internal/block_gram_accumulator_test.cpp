// The Gram accumulator of the sandwich covariances against the dense product, for every model size
// (odd sizes use the zero padding column) and a partial last batch.
#include "cvg_bench/core/estimate/internal/block_gram_accumulator.h"

#include <gtest/gtest.h>

#include <random>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {

TEST(BlockGramAccumulator, EqualsTheDenseGramMatrixForEveryModelSize) {
  std::mt19937_64 gen(4);
  std::normal_distribution<double> n01;
  for (int k = 1; k <= kMaxModelParameters; ++k) {
    const int blocks = 64 * 3 + 17;  // three full batches and a partial one
    Eigen::MatrixXd stacked(4 * blocks, k);
    BlockGramAccumulator acc(k);
    for (int b = 0; b < blocks; ++b) {
      RegressionBlockMatrix x(4, k);
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < k; ++j) x(i, j) = n01(gen) * (1.0 + j);
      stacked.middleRows(4 * b, 4) = x;
      acc.add(x);
    }
    const Eigen::MatrixXd expected = stacked.transpose() * stacked;
    const Eigen::MatrixXd sum = acc.sum();
    EXPECT_LT((sum - expected).norm(), 1e-13 * expected.norm()) << "k = " << k;
    EXPECT_EQ((sum - sum.transpose()).norm(), 0.0);
    // sum() may be called again and the accumulation goes on.
    RegressionBlockMatrix ones = RegressionBlockMatrix::Ones(4, k);
    acc.add(ones);
    EXPECT_NEAR(acc.sum()(k - 1, 0), expected(k - 1, 0) + 4.0, 1e-12 * expected.norm());
  }
}

TEST(BlockGramAccumulator, RejectsBadSizes) {
  EXPECT_THROW(BlockGramAccumulator(0), InputError);
  EXPECT_THROW(BlockGramAccumulator(kMaxModelParameters + 1), InputError);
}

}  // namespace
}  // namespace cvg_bench
