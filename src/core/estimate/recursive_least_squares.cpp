#include "cvg_bench/core/estimate/recursive_least_squares.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {

BlockRecursiveLeastSquares::BlockRecursiveLeastSquares(int num_params, double forgetting)
    : k_(num_params), forgetting_(forgetting) {
  if (num_params < 1 || num_params > kMaxModelParameters)
    throw InputError("RLS needs 1.." + std::to_string(kMaxModelParameters) + " parameters");
  if (!(forgetting > 0.0 && forgetting <= 1.0))
    throw InputError("RLS forgetting factor must lie in (0, 1], got " + std::to_string(forgetting));
}

void BlockRecursiveLeastSquares::initialize(const Eigen::MatrixXd& r_aug, long n_rows) {
  if (r_aug.rows() != k_ + 1 || r_aug.cols() != k_ + 1)
    throw InputError("RLS initialisation: factor of the wrong size");
  const Eigen::MatrixXd r = r_aug.topLeftCorner(k_, k_);
  const double dmax = r.diagonal().cwiseAbs().maxCoeff();
  if (!(dmax > 0.0) || r.diagonal().cwiseAbs().minCoeff() <= 1e-12 * dmax)
    throw AnalysisError(
        "RLS initialisation: the first blocks do not determine all parameters (rank-deficient); "
        "use more initial blocks");
  // P = (R'R)^-1 = R^-1 R^-T from the triangular factor; z = R^-1 Q'y (2.9).
  const Eigen::MatrixXd r_inv =
      r.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(k_, k_));
  p_ = r_inv * r_inv.transpose();
  z_ = r.triangularView<Eigen::Upper>().solve(r_aug.col(k_).head(k_));
  rss_ = r_aug(k_, k_) * r_aug(k_, k_);
  n_eq_ = n_rows;
  initialized_ = true;
}

void BlockRecursiveLeastSquares::update(const RegressionBlockMatrix& d, const Eigen::Vector4d& y) {
  if (!initialized_) throw AnalysisError("RLS update before initialisation");
  using Mk4 = Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::ColMajor, kMaxModelParameters, 4>;
  const Mk4 pr = p_ * d.transpose();       // P r, r = D_{i+1}'
  const Eigen::Matrix4d p_tilde = d * pr;  // r' P r
  Eigen::Matrix4d s = p_tilde;
  s.diagonal().array() += forgetting_;
  const Eigen::LLT<Eigen::Matrix4d> llt(s);
  const Eigen::Vector4d v =
      y - d * z_;  // innovation of the block being added (docs/paper.md item 9)
  const Mk4 gain = llt.solve(pr.transpose()).transpose();  // S = P r (lambda E + r'Pr)^-1
  z_.noalias() += gain * v;
  p_.noalias() -= gain * pr.transpose();
  if (forgetting_ != 1.0) p_ /= forgetting_;
  rss_ = forgetting_ * rss_ + v.dot(llt.solve(v));
  n_eq_ += 4;
  last_p_tilde_max_eig_ =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(p_tilde, Eigen::EigenvaluesOnly)
          .eigenvalues()
          .cwiseAbs()
          .maxCoeff();
}

double BlockRecursiveLeastSquares::sigma() const {
  return n_eq_ > k_ ? std::sqrt(rss_ / static_cast<double>(n_eq_ - k_)) : 0.0;
}

double BlockRecursiveLeastSquares::predictionSigmaBound(double sigma_e) const {
  return sigma_e * std::sqrt(1.0 + last_p_tilde_max_eig_);
}

}  // namespace cvg_bench
