// Block recursive least squares (2.12) with a 4 x 4 innovation, corrected: the innovation pairs
// the block being added, y_{i+1} - D_{i+1} z_i (docs/paper.md item 9; the print pairs it with D_i).
//   S = P r (lambda E + r' P r)^-1,  z += S (y_{i+1} - r' z),  P = (P - S r' P) / lambda,
// r = D_{i+1}' (k x 4). (The paper's S = P r (E - (E + r'Pr)^-1 r'Pr) is the same for lambda = 1.)
// Initialised from a batch QR solve of the first m blocks (2.9), P = (R'R)^-1 from the triangular
// factor. Fixed-capacity matrices: an update allocates nothing.
#pragma once

#include <Eigen/Core>

#include "cvg_bench/core/estimate/least_squares_solver.h"

namespace cvg_bench {

class BlockRecursiveLeastSquares {
 public:
  using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor,
                               kMaxModelParameters, kMaxModelParameters>;
  using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxModelParameters, 1>;

  /// forgetting in (0, 1] (1 = the paper).
  BlockRecursiveLeastSquares(int num_params, double forgetting = 1.0);

  /// Initial batch solve from the QR factor of the first blocks (IncrementalQr::rAug()). Throws
  /// AnalysisError when those blocks do not determine all parameters (rank-deficient R).
  void initialize(const Eigen::MatrixXd& r_aug, long n_rows);
  /// Adds one block (2.12). Requires initialize().
  void update(const RegressionBlockMatrix& d, const Eigen::Vector4d& y);

  bool initialized() const { return initialized_; }
  const Vector& z() const { return z_; }
  /// P_i (the unscaled covariance (D'D)^-1 at forgetting 1).
  const Matrix& p() const { return p_; }
  /// Running residual sum of squares (exact for forgetting 1: sum of innovation quadratic forms).
  double rss() const { return rss_; }
  long numEquations() const { return n_eq_; }
  /// Running sigma-hat = sqrt(rss / (n - k)).
  double sigma() const;
  /// The paper's bound on the prediction error of the last block:
  /// sigma_e^2 (1 + max_j |lambda_j(P~)|), P~ = r' P r of the last update (4x4: max over its 4
  /// eigenvalues, docs/paper.md item 12; sqrt(lambda(P~' P~)) = |lambda(P~)| as P~ is symmetric).
  double predictionSigmaBound(double sigma_e) const;

 private:
  int k_;
  double forgetting_;
  bool initialized_ = false;
  Vector z_;
  Matrix p_;
  double rss_ = 0.0;
  long n_eq_ = 0;
  double last_p_tilde_max_eig_ = 0.0;
};

}  // namespace cvg_bench
