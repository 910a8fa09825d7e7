// Heteroskedasticity-and-autocorrelation-consistent (HAC) covariance of a least-squares estimate:
// the sandwich (J'J)^-1 S (J'J)^-1 with the long-run score covariance S = sum_l w_l Gamma_l
// (Newey-West 1987, Bartlett weights w_l = 1 - |l| / (lag + 1)). The lag comes from Andrews' (1991)
// AR(1) plug-in rule unless given. Used where the equation errors of (2.8) / (3.5) are serially
// correlated (demodulated records, coloured noise), so that the intervals (2.11) stay honest.
#pragma once

#include <Eigen/Core>
#include <string>

namespace cvg_bench {

/// Covariance of a least-squares estimate that stays honest when the residuals are serially
/// correlated: sandwich (J'J)^-1 (sum_l w_l Gamma_l) (J'J)^-1 via QR of J (never forming (J'J)^-1
/// by normal equations), Bartlett (Newey-West) weights, lag chosen from the data (Andrews' AR(1)
/// plug-in) unless lag >= 0 is given.
/// When the lag is chosen, the scores are first prewhitened by a fitted VAR(1) (Andrews-Monahan
/// 1992) and recoloured; a given lag gives the plain Newey-West sum.
struct HacCovariance {
  Eigen::MatrixXd covariance;       ///< p x p
  int lag = 0;                      ///< lag used
  double rho1 = 0.0;                ///< lag-1 autocorrelation of the residuals
  double variance_inflation = 1.0;  ///< mean ratio HAC / iid variance over the parameters
  /// e.g. "HAC Newey-West, Bartlett, lag 2 (Andrews AR(1)) after VAR(1) prewhitening"
  std::string method;
};

/// jacobian: n x p, rows in observation (time) order; residuals: n. lag < 0: chosen from the
/// data. Rank-deficient J: the pseudo-inverse replaces (J'J)^-1 (unidentified directions get zero
/// variance; report them from the rank, see identifiability.h). The meat carries the small-sample
/// factor n / (n - rank). InputError on mismatched sizes, n <= p or non-finite input.
HacCovariance hacCovariance(const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& residuals,
                            int lag = -1);

/// The same for observations stacked block_size rows per time step (e.g. the 4 rows q1, p1, q2,
/// p2 of one sample of (2.8)): rows of one block are summed into one score, lags count blocks,
/// rho1 is the residuals' correlation one block apart. rows must be a multiple of block_size.
HacCovariance hacCovarianceBlocked(const Eigen::MatrixXd& jacobian,
                                   const Eigen::VectorXd& residuals, int block_size, int lag = -1);

/// The same from the per-time-step scores g_t = J_t' e_t (nb x p rows in time order, parameter
/// units) of a system whose QR factor R (J'J = R'R) has the pseudo-inverse r_pinv (p x p), for
/// estimators that stream J (identification.cpp): n_rows and rank give the small-sample factor.
/// rho1 and variance_inflation are left at their defaults.
HacCovariance hacCovarianceFromScores(const Eigen::MatrixXd& scores, const Eigen::MatrixXd& r_pinv,
                                      long n_rows, int rank, int lag = -1);

}  // namespace cvg_bench
