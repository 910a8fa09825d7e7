#include "cvg_bench/core/estimate/uncertainty/correlated_noise_gram.h"

#include <cmath>
#include <sstream>

namespace cvg_bench {

double NoiseCorrelation::at(int lag) const {
  if (lag == 0) return 1.0;
  if (ar1 != 0.0) return std::pow(ar1, lag);
  return lag <= static_cast<int>(lags.size()) ? lags[lag - 1] : 0.0;
}

bool NoiseCorrelation::white() const {
  if (ar1 != 0.0) return false;
  for (double r : lags)
    if (r != 0.0) return false;
  return true;
}

std::string NoiseCorrelation::describe() const {
  std::ostringstream s;
  s.precision(3);
  if (ar1 != 0.0) {
    s << "AR(1) rho = " << ar1;
  } else if (!lags.empty()) {
    s << "rho_1 = " << lags[0] << ", " << lags.size() << " lag(s)";
  } else {
    s << "white";
  }
  return s.str();
}

CorrelatedSensitivityGram::CorrelatedSensitivityGram(int k, NoiseCorrelation rho)
    : k_(k),
      rho_(std::move(rho)),
      s_(Eigen::MatrixXd::Zero(k, k)),
      filtered_(Eigen::MatrixXd::Zero(4, k)) {
  if (rho_.ar1 == 0.0) ring_.assign(rho_.lags.size(), Eigen::MatrixXd::Zero(4, k));
}

void CorrelatedSensitivityGram::add(const RegressionBlockMatrix& w_t, bool first) {
  if (first) in_record_ = 0;
  const Eigen::MatrixXd w = w_t.leftCols(k_);
  s_.noalias() += w.transpose() * w;
  if (rho_.ar1 != 0.0) {
    // sum_{m' < m} rho^(m - m') W_m' = rho F_{m-1}: both cross terms from one product.
    if (in_record_ > 0) {
      const Eigen::MatrixXd cross = rho_.ar1 * (w.transpose() * filtered_);
      s_ += cross + cross.transpose();
      filtered_ = w + rho_.ar1 * filtered_;
    } else {
      filtered_ = w;
    }
  } else if (!ring_.empty()) {
    const long lmax = static_cast<long>(ring_.size());
    for (long l = 1; l <= std::min(in_record_, lmax); ++l) {
      const Eigen::MatrixXd cross =
          rho_.lags[l - 1] * (w.transpose() * ring_[(in_record_ - l) % lmax]);
      s_ += cross + cross.transpose();
    }
    ring_[in_record_ % lmax] = w;
  }
  ++in_record_;
}

Eigen::MatrixXd CorrelatedSensitivityGram::sum() const {
  return s_;
}

}  // namespace cvg_bench
