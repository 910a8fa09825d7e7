#include "cvg_bench/core/estimate/uncertainty/long_run_variance.h"

#include <algorithm>
#include <cmath>

namespace cvg_bench {
namespace {

/// Mean over channels of the lag-l autocovariance (channel means removed), divided by n_channel.
class ChannelAutocovariance {
 public:
  ChannelAutocovariance(const Eigen::VectorXd& r, int channels)
      : channels_(std::max(1, channels)), n_(r.size() / channels_), x_(channels_) {
    for (int c = 0; c < channels_; ++c) {
      x_[c].resize(n_);
      for (long i = 0; i < n_; ++i) x_[c][i] = r[i * channels_ + c];
      x_[c].array() -= x_[c].mean();
    }
  }
  long length() const { return n_; }
  /// Autocorrelation at lag l (autocovariances averaged over channels, then normalised).
  double rho(long l) const {
    double num = 0.0, den = 0.0;
    for (int c = 0; c < channels_; ++c) {
      num += x_[c].head(n_ - l).dot(x_[c].tail(n_ - l));
      den += x_[c].squaredNorm();
    }
    return den > 0.0 ? num / den : 0.0;
  }

 private:
  int channels_;
  long n_;
  std::vector<Eigen::VectorXd> x_;
};

}  // namespace

double longRunVarianceFactor(const Eigen::VectorXd& residuals, int channels, double window_factor,
                             int max_lag) {
  const ChannelAutocovariance acf(residuals, channels);
  const long cap = std::min<long>(max_lag, acf.length() / 4);
  double c = 1.0;
  for (long m = 1; m <= cap; ++m) {
    c += 2.0 * acf.rho(m);
    if (m >= window_factor * c) break;
  }
  return std::max(1.0, c);
}

double longRunVarianceFactor(const std::vector<double>& rho) {
  double c = 1.0;
  for (double r : rho) c += 2.0 * r;
  return std::max(1.0, c);
}

double lagOneCorrelation(const Eigen::VectorXd& residuals, int channels) {
  const ChannelAutocovariance acf(residuals, channels);
  return acf.length() > 2 ? acf.rho(1) : 0.0;
}

}  // namespace cvg_bench
