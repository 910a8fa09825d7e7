// Arithmetic on 4 x k regression blocks in the inner loops of the batch estimator (one 4-wide
// vector per column; compiled also for AVX2/FMA with dispatch at load time).
#pragma once

#include <Eigen/Core>

#include "cvg_bench/core/estimate/least_squares_solver.h"

namespace cvg_bench {

/// out = w0 a + w1 b + w2 c (the quadrature of D-bar_i, (2.7)); all 4 x k, out resized by caller.
void weightedBlockSum(double w0, const RegressionBlockMatrix& a, double w1,
                      const RegressionBlockMatrix& b, double w2, const RegressionBlockMatrix& c,
                      RegressionBlockMatrix& out);

/// y - d z (the equation errors of one block); z.size() == d.cols().
Eigen::Vector4d blockResidual(const RegressionBlockMatrix& d, const Eigen::VectorXd& z,
                              const Eigen::Vector4d& y);

}  // namespace cvg_bench
