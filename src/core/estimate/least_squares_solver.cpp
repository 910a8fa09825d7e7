#include "cvg_bench/core/estimate/least_squares_solver.h"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <string>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/internal/householder_panel_update.h"

namespace cvg_bench {
namespace {

constexpr int kBufferRows = 256;

}  // namespace

IncrementalQr::IncrementalQr(int num_params) : k_(num_params) {
  if (num_params < 1 || num_params > kMaxModelParameters)
    throw InputError("least squares needs 1.." + std::to_string(kMaxModelParameters) +
                     " parameters, got " + std::to_string(num_params));
  r_aug_ = Eigen::MatrixXd::Zero(k_ + 1, k_ + 1);
  buffer_.resize(kBufferRows + 8, k_ + 1);  // + 8: columns 2 kB apart would alias in the L1 cache
}

void IncrementalQr::addRows(const Eigen::Ref<const Eigen::MatrixXd>& a,
                            const Eigen::Ref<const Eigen::VectorXd>& y) {
  if (a.cols() != k_ || a.rows() != y.size())
    throw InputError("least squares: rows of size " + std::to_string(a.cols()) + " for " +
                     std::to_string(k_) + " parameters");
  for (Eigen::Index r = 0; r < a.rows(); ++r) {
    buffer_.row(buffered_).head(k_) = a.row(r);
    buffer_(buffered_, k_) = y[r];
    if (++buffered_ == kBufferRows) flush();
  }
  n_rows_ += a.rows();
}

void IncrementalQr::addBlock(const RegressionBlockMatrix& d, const Eigen::Vector4d& y) {
  if (buffered_ + 4 > kBufferRows) flush();
  buffer_.block(buffered_, 0, 4, k_) = d;
  buffer_.block(buffered_, k_, 4, 1) = y;
  buffered_ += 4;
  n_rows_ += 4;
}

const Eigen::MatrixXd& IncrementalQr::rAug() {
  flush();
  return r_aug_;
}

// Householder reflections on [R_aug; B] (householder_panel_update.h): column j's reflector has
// nonzeros only in row j of R_aug and in the buffered rows B, so the cost is ~2 m k^2 for m rows.
void IncrementalQr::flush() {
  const int m = buffered_;
  if (m == 0) return;
  const int rows4 = (m + 3) / 4 * 4;  // zero rows change nothing
  if (rows4 > m) buffer_.middleRows(m, rows4 - m).setZero();
  householderPanelUpdate(r_aug_.data(), static_cast<int>(r_aug_.outerStride()), buffer_.data(),
                         static_cast<int>(buffer_.outerStride()), rows4, k_ + 1);
  buffered_ = 0;
}

LeastSquaresSolution solveTriangular(const Eigen::MatrixXd& r_aug, long n_rows,
                                     double relative_tolerance) {
  if (!(relative_tolerance > 0.0 && relative_tolerance < 1.0))
    throw InputError("rank tolerance must lie in (0, 1), got " +
                     std::to_string(relative_tolerance));
  const int k = static_cast<int>(r_aug.rows()) - 1;
  const Eigen::MatrixXd r = r_aug.topLeftCorner(k, k).triangularView<Eigen::Upper>();
  const Eigen::VectorXd qty = r_aug.col(k).head(k);
  LeastSquaresSolution s;
  s.n_rows = n_rows;
  s.relative_tolerance = relative_tolerance;
  s.column_norms = r.colwise().norm().transpose();
  Eigen::VectorXd scale = s.column_norms;
  for (int j = 0; j < k; ++j)
    if (!(scale[j] > 0.0)) scale[j] = 1.0;
  const Eigen::MatrixXd rs = r * scale.cwiseInverse().asDiagonal();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(rs, Eigen::ComputeFullU | Eigen::ComputeFullV);
  s.singular_values = svd.singularValues();
  const double cut = relative_tolerance * (k > 0 ? s.singular_values[0] : 0.0);
  s.rank = 0;
  for (int i = 0; i < k; ++i)
    if (s.singular_values[i] > cut && s.singular_values[i] > 0.0) ++s.rank;
  const int rk = s.rank;
  const Eigen::MatrixXd ur = svd.matrixU().leftCols(rk);
  const Eigen::MatrixXd vr = svd.matrixV().leftCols(rk);
  const Eigen::VectorXd inv_sv = s.singular_values.head(rk).cwiseInverse();
  s.r_pinv = scale.cwiseInverse().asDiagonal() * vr * inv_sv.asDiagonal() * ur.transpose();
  s.z = s.r_pinv * qty;
  s.unscaled_covariance = s.r_pinv * s.r_pinv.transpose();
  const double explained = (ur.transpose() * qty).squaredNorm();
  s.rss = std::max(0.0, r_aug(k, k) * r_aug(k, k) + qty.squaredNorm() - explained);
  if (rk < k) {
    const Eigen::MatrixXd nul = scale.cwiseInverse().asDiagonal() * svd.matrixV().rightCols(k - rk);
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(nul);
    s.null_space = qr.householderQ() * Eigen::MatrixXd::Identity(k, k - rk);
  } else {
    s.null_space.resize(k, 0);
  }
  return s;
}

LeastSquaresSolution solveLeastSquares(const Eigen::MatrixXd& a, const Eigen::VectorXd& y,
                                       double relative_tolerance) {
  IncrementalQr qr(static_cast<int>(a.cols()));
  qr.addRows(a, y);
  return solveTriangular(qr.rAug(), qr.numRows(), relative_tolerance);
}

}  // namespace cvg_bench
