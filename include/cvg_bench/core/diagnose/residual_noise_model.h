// The noise model under which `explain`'s adequacy test is calibrated (the lack-of-fit
// verdict must hold its false-alarm rate on demodulated records and coloured noise).
//
// Residuals of an adequate model are the measurement noise; when that noise is correlated, sign
// runs and signature correlations of the raw residuals look like structure. The residuals are
// therefore whitened, channel by channel, by an autoregressive filter
//   w_t = e_t - sum_{k=1..p} a_k e_{t-k}
// before the runs test and the signature:
//   known correlation rho_1..rho_L (a demodulated record's noise_correlation): AR(p) by
//     Levinson-Durbin on rho (p = min(L, 30));
//   otherwise AR(1) of the residuals after a smooth part (Legendre polynomials in time) is removed,
//   its lag-1 correlation corrected for that projection and capped at 0.95
//   (noiseModelFromDetrendedResiduals, used by explain). The older variogram-ratio estimate
//     rho = (1 - r_2) / (1 - r_1) - 1,   r_l the lag-l residual autocorrelation,
//   (noiseModelFromResiduals) is fooled by a curved misfit larger than the noise: its increments
//   grow as l^2, the ratio tends to 4 and rho to its clamp, whitening the misfit away (the
//   Foucault record, docs/examples/foucault.md).
// A smooth misfit passes the filter scaled by (1 - sum a_k), so it stays visible to the tests.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace cvg_bench {

struct ResidualNoiseModel {
  std::vector<double> ar;  ///< a_1..a_p of the whitening filter (empty: white)
  double rho1 = 0.0;       ///< lag-1 correlation of the model's noise
  std::string description;
};

/// AR(p) of known correlations (Levinson-Durbin), p <= max_order.
ResidualNoiseModel noiseModelFromCorrelation(const std::vector<double>& rho, int max_order = 30);

/// AR(1) from the variogram ratio of residuals with `channels` interleaved components (row r is
/// channel r % channels), rho clamped to [-0.5, 0.98]; white when |rho| < min_rho.
ResidualNoiseModel noiseModelFromResiduals(const Eigen::VectorXd& residuals, int channels,
                                           double min_rho = 0.05);

/// AR(1) of each channel's residuals after a least-squares fit of Legendre polynomials of degree
/// <= `degree` in the sample index is removed (a smooth misfit has lag-1 correlation ~1 and would
/// otherwise pass for correlated noise), Yule-Walker rho averaged over the channels, capped at
/// `ceiling` (a correlation time beyond ~1 / (1 - ceiling) samples is not told from a misfit on one
/// record); white when |rho| < min_rho.
ResidualNoiseModel noiseModelFromDetrendedResiduals(const Eigen::VectorXd& residuals, int channels,
                                                    int degree = 5, double ceiling = 0.95,
                                                    double min_rho = 0.05);

/// `known` followed by an AR(1) of what it leaves: the residuals whitened by `known` (its first p
/// samples per channel left out), noiseModelFromDetrendedResiduals of those, and the two filters
/// composed, (1 - sum a_k L^k)(1 - b L) = 1 - sum c_j L^j, c_j = a_j - b a_{j-1} (a_0 = -1,
/// a_{p+1} = 0). `known` itself when nothing is left or fewer than 16 samples a channel.
ResidualNoiseModel withDetrendedAr1(const ResidualNoiseModel& known,
                                    const Eigen::VectorXd& residuals, int channels);

/// Applies the whitening filter to each channel (the first p samples of a channel use the
/// available past only).
Eigen::VectorXd whiten(const Eigen::VectorXd& residuals, int channels,
                       const ResidualNoiseModel& model);

}  // namespace cvg_bench
