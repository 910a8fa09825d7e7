// Serial correlation of residuals, four rows (q1, p1, q2, p2) per time step: the lag-l
// correlations, the test of the lag-1 one against what independent noise predicts, and the AR(1)
// noise model of the slow samples that the differenced free-decay regression (2.7) implies.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace cvg_bench {

/// c_l = sum_t r_t . r_{t-l} / sum_t |r_t|^2, l = 1 .. max_lag; lags never cross a record start.
class ResidualLagAccumulator {
 public:
  explicit ResidualLagAccumulator(int max_lag);
  /// The next time step's residual 4-vector.
  void add(const Eigen::Vector4d& r);
  /// The following residuals start a new record.
  void startRecord() {
    in_record_ = 0;
    head_ = 0;
  }
  std::vector<double> correlations() const;
  long steps() const { return steps_; }

 private:
  int max_lag_;
  std::vector<Eigen::Vector4d> ring_;
  std::vector<double> cross_;
  double sum_sq_ = 0.0;
  long in_record_ = 0, steps_ = 0;
  int head_ = 0;
};

/// Two-sided test of the lag-1 correlation: z = (c_1 - expected) / sqrt(variance_factor / steps)
/// (Bartlett's formula: variance_factor = 1 + 2 sum rho_l^2 of the null, 1 for white residuals,
/// 1.5 for the MA(2) residuals of (2.7) under white noise on q).
struct SerialCorrelationTest {
  double lag1 = 0.0;      ///< measured c_1
  double expected = 0.0;  ///< c_1 under independent noise
  double z = 0.0;
  bool correlated = false;  ///< |z| > kSerialCorrelationZ
  long steps = 0;
};
/// Two-sided 1 % level.
constexpr double kSerialCorrelationZ = 2.576;
SerialCorrelationTest testLagOne(double lag1, double expected, double variance_factor, long steps);

/// Residual correlation at block lag l of y_i - D-bar_i z in (2.7) when the noise on each slow
/// variable is AR(1) with coefficient rho and the samples are slow (h ||G|| << 1): the residual is
/// 2 (eps_{i+1} - eps_{i-1}), so c_1 = rho / 2, c_l = -(1 - rho^2) rho^(l-2) / 2 for l >= 2.
double differencedAr1Correlation(double rho, int lag);
/// rho in [-0.99, 0.995] minimizing sum_l (c_l - differencedAr1Correlation(rho, l))^2.
double fitDifferencedAr1(const std::vector<double>& c);

}  // namespace cvg_bench
