#include "cvg_bench/core/estimate/uncertainty/fitted_residual_ar1.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

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

/// Rows x lags up to which the lag products are formed one by one (cheap there; the same
/// arithmetic as before the recursion existed), above it the recursion (LagSums).
constexpr double kDirectRowLags = 2e7;

/// E[r'Lr] / E[r'r] at rho, by whichever of the two forms the record's size calls for.
class Expectation {
 public:
  Expectation(const Eigen::MatrixXd& j, const Eigen::MatrixXd& c, int channels, int lags)
      : j_(j), c_(c), channels_(channels) {
    if (static_cast<double>(j.rows()) * lags <= kDirectRowLags)
      m_ = lagProducts(j, channels, lags);
    else
      sums_ = std::make_unique<LagSums>(j, channels, lags);
  }
  double operator()(double rho) const {
    return sums_ ? expectation(*sums_, c_, j_.rows(), channels_, rho)
                 : expectation(m_, c_, j_.rows(), channels_, rho);
  }

 private:
  const Eigen::MatrixXd& j_;
  const Eigen::MatrixXd& c_;
  int channels_;
  std::vector<Eigen::MatrixXd> m_;
  std::unique_ptr<LagSums> sums_;
};

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
  const Expectation e(j, c, channels, lagsFor(hi, j.rows() / channels));
  auto f = [&](double rho) { return e(rho) - observed_lag1; };
  if (f(hi) <= 0.0) return hi;
  if (f(lo) >= 0.0) return lo;
  // Bisection, 40 steps: on an ill-conditioned fit f is rough at the 1e-3 level (the traces of
  // C S cancel), so a faster root finder can stop at another sign change (2e-4 apart in rho on the
  // Foucault record); the bisection's path is kept.
  double a = lo, b = hi;
  for (int it = 0; it < 40; ++it) {
    const double mid = 0.5 * (a + b);
    (f(mid) < 0.0 ? a : b) = mid;
  }
  return 0.5 * (a + b);
}

}  // namespace cvg_bench
