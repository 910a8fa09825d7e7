// Sum of X'X over a stream of 4 x k blocks X (the "meat" of the sandwich covariances of
// identification.cpp: sum_m W_m W_m' for free decay, sum_j s_j s_j' for sweeps with four score
// vectors s_j as the rows of X). Each product entry (i, j) is kept as four partial sums, one per
// row of X, in a 4-wide vector and the four are added once at the end, so a block costs one
// vector multiply-add per entry of the lower triangle and no horizontal sums.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "cvg_bench/core/estimate/least_squares_solver.h"

namespace cvg_bench {

class BlockGramAccumulator {
 public:
  /// k = number of columns of the blocks (1..kMaxModelParameters).
  explicit BlockGramAccumulator(int k);
  /// Adds X'X of one 4 x k block (buffered).
  void add(const RegressionBlockMatrix& x);
  /// The k x k symmetric sum so far.
  Eigen::MatrixXd sum();

 private:
  void flush();
  int k_, kpad_;                 // kpad_ = k rounded up to even (zero column)
  int in_batch_ = 0;             // blocks waiting in batch_
  std::vector<double> batch_;    // block s, column c at (s kpad_ + c) * 4
  std::vector<double> partial_;  // entry (i, j) at (i kpad_ + j) * 4, lower triangle used
};

}  // namespace cvg_bench
