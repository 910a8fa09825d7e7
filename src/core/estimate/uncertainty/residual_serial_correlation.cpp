#include "cvg_bench/core/estimate/uncertainty/residual_serial_correlation.h"

#include <cmath>

namespace cvg_bench {

ResidualLagAccumulator::ResidualLagAccumulator(int max_lag)
    : max_lag_(max_lag), ring_(static_cast<size_t>(max_lag)), cross_(max_lag, 0.0) {}

void ResidualLagAccumulator::add(const Eigen::Vector4d& r) {
  sum_sq_ += r.squaredNorm();
  // ring_[head_] is the next slot; the previous residuals sit at head_ - 1, head_ - 2, ...
  // (wrapped without a division per lag: this runs once per time step of a 10^6-sample record).
  const int avail = static_cast<int>(std::min<long>(in_record_, max_lag_));
  int slot = head_;
  for (int l = 0; l < avail; ++l) {
    slot = slot == 0 ? max_lag_ - 1 : slot - 1;
    cross_[l] += r.dot(ring_[slot]);
  }
  ring_[head_] = r;
  head_ = head_ + 1 == max_lag_ ? 0 : head_ + 1;
  ++in_record_;
  ++steps_;
}

std::vector<double> ResidualLagAccumulator::correlations() const {
  std::vector<double> c(max_lag_, 0.0);
  if (!(sum_sq_ > 0.0)) return c;
  for (int l = 0; l < max_lag_; ++l) c[l] = cross_[l] / sum_sq_;
  return c;
}

SerialCorrelationTest testLagOne(double lag1, double expected, double variance_factor, long steps) {
  SerialCorrelationTest t;
  t.lag1 = lag1;
  t.expected = expected;
  t.steps = steps;
  if (steps < 3) return t;
  t.z = (lag1 - expected) / std::sqrt(variance_factor / static_cast<double>(steps));
  t.correlated = std::fabs(t.z) > kSerialCorrelationZ;
  return t;
}

double differencedAr1Correlation(double rho, int lag) {
  if (lag == 1) return rho / 2.0;
  return -(1.0 - rho * rho) * std::pow(rho, lag - 2) / 2.0;
}

double fitDifferencedAr1(const std::vector<double>& c) {
  const auto misfit = [&](double rho) {
    double s = 0.0;
    for (size_t l = 0; l < c.size(); ++l) {
      const double d = c[l] - differencedAr1Correlation(rho, static_cast<int>(l) + 1);
      s += d * d;
    }
    return s;
  };
  double best = 0.0, best_misfit = misfit(0.0);
  for (double rho = -0.99; rho <= 0.995; rho += 0.005) {
    const double m = misfit(rho);
    if (m < best_misfit) best_misfit = m, best = rho;
  }
  // Golden-section refinement around the grid minimum.
  double a = std::max(-0.99, best - 0.005), b = std::min(0.995, best + 0.005);
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int it = 0; it < 40; ++it) {
    const double x1 = b - g * (b - a), x2 = a + g * (b - a);
    if (misfit(x1) < misfit(x2))
      b = x2;
    else
      a = x1;
  }
  return 0.5 * (a + b);
}

}  // namespace cvg_bench
