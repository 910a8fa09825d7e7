#include "cvg_bench/core/estimate/fitted_residual_ar1.h"

#include <algorithm>
#include <boost/math/tools/roots.hpp>
#include <cmath>
#include <cstdint>

namespace cvg_bench {
namespace {

/// The lag sums the expectation needs, M_d = sum_i J_{i+cd}' J_i over rows c = `channels` apart:
/// M_0, M_1 and the geometric sum Q(rho) = sum_{d=1}^{L} rho^d M_d (L = `lags`, fewer when the
/// record is shorter). Q = rho sum_i Z_i' J_i with Z_i = sum_{d=1}^{L} rho^(d-1) J_{i+cd}, by the
/// backward recursion Z_i = J_{i+c} + rho Z_{i+c} - rho^L J_{i+c(L+1)}: one pass over J for any L
/// (the sum of L lag products costs L passes).
class LagSums {
 public:
  LagSums(const Eigen::MatrixXd& j, int channels, int lags)
      : j_(j), c_(channels), lags_(std::max(1, lags)) {
    const long n = j.rows();
    m0_ = j.transpose() * j;
    m1_ = Eigen::MatrixXd::Zero(j.cols(), j.cols());
    if (c_ < n) m1_ = j.bottomRows(n - c_).transpose() * j.topRows(n - c_);
  }
  const Eigen::MatrixXd& m0() const { return m0_; }
  const Eigen::MatrixXd& m1() const { return m1_; }

  /// sum_{d=1}^{L} rho^(d-1) M_d (= Q / rho).
  Eigen::MatrixXd weighted(double rho) const {
    const long n = j_.rows(), p = j_.cols(), c = c_;
    const long block = std::max<long>(c, 4096 / c * c);
    const long tail_lag = c * (static_cast<long>(lags_) + 1);
    const double tail_w = std::pow(rho, lags_);
    Eigen::MatrixXd q = Eigen::MatrixXd::Zero(p, p);
    Eigen::MatrixXd z(block, p), carry = Eigen::MatrixXd::Zero(c, p);
    for (long end = n; end > 0; end -= block) {
      const long start = std::max<long>(0, end - block), rows = end - start;
      for (long k = 0; k < p; ++k) {
        const double* x = j_.col(k).data();
        double* zk = z.col(k).data();
        for (long i = end - 1; i >= start; --i) {
          const long next = i + c;
          double v = 0.0;
          if (next < n) {
            const double z_next = next < end ? zk[next - start] : carry(next - end, k);
            v = x[next] + rho * z_next;
            if (i + tail_lag < n) v -= tail_w * x[i + tail_lag];
          }
          zk[i - start] = v;
        }
      }
      q.noalias() += z.topRows(rows).transpose() * j_.middleRows(start, rows);
      if (rows >= c) carry = z.topRows(c);
    }
    return q;
  }

 private:
  const Eigen::MatrixXd& j_;
  long c_;
  int lags_;
  Eigen::MatrixXd m0_, m1_;
};

int lagsFor(double rho, long steps) {
  if (!(rho > 0.0)) return 1;
  const int l = static_cast<int>(std::ceil(std::log(1e-4) / std::log(std::min(rho, 0.999))));
  return static_cast<int>(std::max<long>(1, std::min<long>(l, steps / 4)));
}

double expectation(const LagSums& m, const Eigen::MatrixXd& c, long n, int channels, double rho) {
  // S = M_0 + Q + Q'; X = J' Sigma L J = sum_{d>=1} rho^(d-1) M_d + sum_{e>=0} rho^(e+1) M_e'
  //   = W + rho (M_0' + Q'), W = Q / rho; A = (X + X') / 2; B = (M_1 + M_1') / 2.
  const Eigen::MatrixXd w = m.weighted(rho);
  const Eigen::MatrixXd q = rho * w;
  const Eigen::MatrixXd s = m.m0() + q + q.transpose();
  const Eigen::MatrixXd x = w + rho * (m.m0().transpose() + q.transpose());
  const Eigen::MatrixXd a = 0.5 * (x + x.transpose());
  const Eigen::MatrixXd b = 0.5 * (m.m1() + m.m1().transpose());
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
  const LagSums m(j, channels, lagsFor(rho, j.rows() / channels));
  return expectation(m, c, j.rows(), channels, rho);
}

double fittedResidualAr1(const Eigen::MatrixXd& j, const Eigen::MatrixXd& c, int channels,
                         double observed_lag1) {
  channels = std::max(1, channels);
  if (!(observed_lag1 > 0.0) || observed_lag1 >= 1.0 || j.rows() <= 2 * j.cols() ||
      c.rows() != j.cols())
    return observed_lag1;
  const double lo = observed_lag1, hi = 1.0 - 0.5 * (1.0 - observed_lag1);
  const LagSums m(j, channels, lagsFor(hi, j.rows() / channels));
  auto f = [&](double rho) { return expectation(m, c, j.rows(), channels, rho) - observed_lag1; };
  const double f_hi = f(hi);
  if (f_hi <= 0.0) return hi;
  const double f_lo = f(lo);
  if (f_lo >= 0.0) return lo;
  // The root of the bracketed, smooth f by TOMS 748 (~10 evaluations, one pass over J each) to a
  // bracket of ~2e-13 relative: the 40 bisection steps' precision at a quarter of the passes.
  std::uintmax_t max_iter = 60;
  const auto r = boost::math::tools::toms748_solve(
      f, lo, hi, f_lo, f_hi, boost::math::tools::eps_tolerance<double>(43), max_iter);
  return 0.5 * (r.first + r.second);
}

}  // namespace cvg_bench
