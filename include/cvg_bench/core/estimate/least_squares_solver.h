// Linear least squares by orthogonal factorization, never by inverting the normal equations.
//
// IncrementalQr keeps the triangular factor of the augmented system [A | y] while rows arrive in
// blocks (tall systems are never stored: 10^6 samples x 14 parameters stream through ~30 kB).
// Adding rows applies Householder reflections to [R_aug; new rows]; the top part is already
// triangular, so each reflection touches one row of R_aug and the new rows only.
// solveTriangular then equilibrates the columns (unit column norms), takes the SVD of the scaled
// k x k factor, and decides the numerical rank with a relative singular-value tolerance.
#pragma once

#include <Eigen/Core>

#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

/// One 4-row block of a regression (a block of (2.8) or (3.5)): 4 x k with fixed capacity.
using RegressionBlockMatrix =
    Eigen::Matrix<double, 4, Eigen::Dynamic, Eigen::ColMajor, 4, kMaxModelParameters>;

class IncrementalQr {
 public:
  /// num_params = k (1..kMaxModelParameters).
  explicit IncrementalQr(int num_params);

  /// Adds the rows a (m x k) with right-hand side y (m).
  void addRows(const Eigen::Ref<const Eigen::MatrixXd>& a,
               const Eigen::Ref<const Eigen::VectorXd>& y);
  /// Adds one 4-row block (buffered; flushed by rAug()).
  void addBlock(const RegressionBlockMatrix& d, const Eigen::Vector4d& y);

  int numParams() const { return k_; }
  /// Rows added so far.
  long numRows() const { return n_rows_; }
  /// The (k+1) x (k+1) upper-triangular factor of [A | y]: top-left k x k is R, the top k entries
  /// of the last column are Q^T y, and the corner's square is the residual sum of squares of the
  /// full-rank solution.
  const Eigen::MatrixXd& rAug();

 private:
  void flush();
  int k_;
  long n_rows_ = 0;
  Eigen::MatrixXd r_aug_;
  Eigen::MatrixXd buffer_;  // rows waiting to be folded in, [A | y]
  int buffered_ = 0;
};

/// A least-squares solution with its rank diagnostics.
struct LeastSquaresSolution {
  Eigen::VectorXd z;                ///< minimum-norm (in equilibrated units) solution
  int rank = 0;                     ///< numerical rank
  double relative_tolerance = 0;    ///< singular values <= tol * max are treated as 0
  long n_rows = 0;                  ///< equations
  double rss = 0.0;                 ///< residual sum of squares at z
  Eigen::VectorXd column_norms;     ///< norms of the columns of A (equilibration scale)
  Eigen::VectorXd singular_values;  ///< of the equilibrated matrix, descending
  /// (A^T A)^+ (the pseudo-inverse; equals (A^T A)^{-1} at full rank), parameter units.
  Eigen::MatrixXd unscaled_covariance;
  /// Orthonormal basis (in parameter units, columns normalized) of the null space of A: k x (k -
  /// rank).
  Eigen::MatrixXd null_space;
  /// Pseudo-inverse of R (k x k) in parameter units: z = r_pinv * (Q^T y); used for sandwich forms.
  Eigen::MatrixXd r_pinv;
};

/// Solves from the factor of IncrementalQr::rAug(). relative_tolerance in (0, 1).
LeastSquaresSolution solveTriangular(const Eigen::MatrixXd& r_aug, long n_rows,
                                     double relative_tolerance);
/// Convenience: a dense system A z = y.
LeastSquaresSolution solveLeastSquares(const Eigen::MatrixXd& a, const Eigen::VectorXd& y,
                                       double relative_tolerance);

}  // namespace cvg_bench
