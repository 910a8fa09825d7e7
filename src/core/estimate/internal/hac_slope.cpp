#include "cvg_bench/core/estimate/internal/hac_slope.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "cvg_bench/core/estimate/uncertainty/hac_covariance.h"
#include "cvg_bench/core/estimate/uncertainty/student_t.h"

namespace cvg_bench {

ParameterEstimate hacSlope(const std::vector<double>& t, const std::vector<double>& y,
                           double confidence) {
  const int n = static_cast<int>(t.size());
  ParameterEstimate p;
  if (n < 6 || y.size() != t.size()) return p;
  Eigen::MatrixXd j(n, 2);
  Eigen::VectorXd v(n);
  const double t0 = t[n / 2];
  for (int i = 0; i < n; ++i) {
    j(i, 0) = 1.0;
    j(i, 1) = t[i] - t0;
    v(i) = y[i];
  }
  const Eigen::VectorXd beta = j.colPivHouseholderQr().solve(v);
  const Eigen::VectorXd e = v - j * beta;
  const HacCovariance h = hacCovariance(j, e);
  p.value = beta(1);
  p.std_error = std::sqrt(std::max(0.0, h.covariance(1, 1)));
  const double s = studentQuantile(confidence, n - 2);
  p.ci_low = p.value - s * p.std_error;
  p.ci_high = p.value + s * p.std_error;
  return p;
}

}  // namespace cvg_bench
