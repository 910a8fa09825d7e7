#include "cvg_bench/core/estimate/fitted_residual_ar1.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace cvg_bench {
namespace {

/// M_d = sum_t J_t' J_{t-d} over rows `channels * d` apart, d = 0..max_lag (p x p each).
std::vector<Eigen::MatrixXd> lagProducts(const Eigen::MatrixXd& j, int channels, int max_lag) {
  std::vector<Eigen::MatrixXd> m;
  const long n = j.rows();
  for (int d = 0; d <= max_lag && channels * static_cast<long>(d) < n; ++d) {
    const long rows = n - channels * static_cast<long>(d);
    m.push_back(j.bottomRows(rows).transpose() * j.topRows(rows));
  }
  return m;
}

int lagsFor(double rho, long steps) {
  if (!(rho > 0.0)) return 1;
  const int l = static_cast<int>(std::ceil(std::log(1e-4) / std::log(std::min(rho, 0.999))));
  return static_cast<int>(std::max<long>(1, std::min<long>(l, steps / 4)));
}

double expectation(const std::vector<Eigen::MatrixXd>& m, const Eigen::MatrixXd& c, long n,
                   int channels, double rho) {
  // S = M_0 + sum_d rho^d (M_d + M_d'); X = J' Sigma L J = sum_{d>=1} rho^(d-1) M_d +
  // sum_{e>=0} rho^(e+1) M_e'; A = (X + X') / 2; B = (M_1 + M_1') / 2.
  Eigen::MatrixXd s = m[0], x = rho * m[0].transpose();
  double w = 1.0;
  for (size_t d = 1; d < m.size(); ++d) {
    x += w * m[d];  // rho^(d-1)
    w *= rho;       // rho^d
    s += w * (m[d] + m[d].transpose());
    x += w * rho * m[d].transpose();
  }
  const Eigen::MatrixXd a = 0.5 * (x + x.transpose());
  const Eigen::MatrixXd b = m.size() > 1 ? Eigen::MatrixXd(0.5 * (m[1] + m[1].transpose()))
                                         : Eigen::MatrixXd::Zero(c.rows(), c.cols());
  const Eigen::MatrixXd cs = c * s;
  const double rr = static_cast<double>(n) - cs.trace();
  const double rlr =
      static_cast<double>(n - channels) * rho - 2.0 * (c * a).trace() + (b * cs * c).trace();
  return rr > 0.0 ? rlr / rr : rho;
}

}  // namespace

double expectedResidualLag1(const Eigen::MatrixXd& j, const Eigen::MatrixXd& c, int channels,
                            double rho) {
  channels = std::max(1, channels);
  const auto m = lagProducts(j, channels, lagsFor(rho, j.rows() / channels));
  return expectation(m, c, j.rows(), channels, rho);
}

double fittedResidualAr1(const Eigen::MatrixXd& j, const Eigen::MatrixXd& c, int channels,
                         double observed_lag1) {
  channels = std::max(1, channels);
  if (!(observed_lag1 > 0.0) || observed_lag1 >= 1.0 || j.rows() <= 2 * j.cols() ||
      c.rows() != j.cols())
    return observed_lag1;
  double lo = observed_lag1, hi = 1.0 - 0.5 * (1.0 - observed_lag1);
  const auto m = lagProducts(j, channels, lagsFor(hi, j.rows() / channels));
  auto f = [&](double rho) { return expectation(m, c, j.rows(), channels, rho) - observed_lag1; };
  if (f(hi) <= 0.0) return hi;
  if (f(lo) >= 0.0) return lo;
  for (int it = 0; it < 40; ++it) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) < 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace cvg_bench
