// How much correlated residuals reduce the information in a sum of squares (for the selection
// criterion and the adequacy test of `explain`).
//
// For a stationary series with autocorrelation rho_l, the variance of a sum of n values is
// n sigma^2 c with the long-run variance factor c = 1 + 2 sum_{l>=1} rho_l; n / c is the effective
// sample size. Estimated from residuals with Sokal's automatic window: c(M) = 1 + 2 sum_{l<=M}
// rho_l, M the smallest lag with M >= window_factor * c(M) (AR(1) rho = 0.9: c = 19, M ~ 100).
// Residuals of free decay and forced fits hold 4 interleaved channels (q1, p1, q2, p2 rows); the
// autocorrelations are those of each channel, averaged over the channels.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace cvg_bench {

/// c of a series with `channels` interleaved components (row r is channel r % channels), >= 1;
/// the window is at most max_lag lags and a quarter of a channel's length. 1 when too short.
double longRunVarianceFactor(const Eigen::VectorXd& residuals, int channels,
                             double window_factor = 5.0, int max_lag = 1000);

/// c = 1 + 2 sum rho_l of known correlations (a demodulated record's noise_correlation), >= 1.
double longRunVarianceFactor(const std::vector<double>& rho);

/// Lag-1 autocorrelation of the channels (averaged), for reports.
double lagOneCorrelation(const Eigen::VectorXd& residuals, int channels);

}  // namespace cvg_bench
