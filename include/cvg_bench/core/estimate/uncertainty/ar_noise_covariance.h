// Covariance of a ring-down envelope fit (ringdown_fit.h) under the correlated residuals real
// records show (lock-in low-pass, source drift, spectrum-analyser video filter).
//
// 1. Detection: the lag-1 autocorrelation of the weighted ln A residuals against its white-noise
//    band +- 2.576 / sqrt(n) (two-sided 1 %) and the Ljung-Box statistic over 10 lags (1 %).
// 2. White residuals: the Cramer-Rao covariance sigma^2 (J'J)^-1 (R of the QR of J).
// 3. Correlated residuals: an AR(p) noise model of the residuals (least squares by QR, p <= 12 by
//    BIC), its autocovariance gamma_l from the Yule-Walker recursion, and the sandwich
//    (J'J)^-1 (sum_{i,j} gamma_|i-j| J_i J_j') (J'J)^-1, the lag sum truncated where the model's
//    autocorrelation falls below 1e-4; the variance is scaled so that gamma_0 is the residuals'
//    variance. The effective sample size n / c (c = the long-run variance factor of the model) sets
//    the Student quantile's degrees of freedom.
// 4. Block check (whether or not correlation was detected): the cluster sandwich of the scores
//    J_i' r_i summed over kBlocks contiguous blocks, (J'J)^-1 [B / (B - p) sum_b S_b S_b']
//    (J'J)^-1, which needs no noise model and holds when the correlation changes along the record
//    (relative noise at the start, filtered additive noise near the floor) or outlasts an AR(12)
//    model. Each parameter keeps the larger of its two standard errors (correlations from step
//    2/3); where the block one wins, the Student quantile has B - p degrees of freedom.
// The Cramer-Rao bound for white noise (step 2) is returned beside it for the report.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace cvg_bench {

struct ArNoiseCovariance {
  Eigen::MatrixXd covariance;  ///< p x p, the honest one (equal to crb when white)
  Eigen::MatrixXd crb;         ///< sigma^2 (J'J)^-1, white noise
  bool correlated = false;
  double rho1 = 0.0;             ///< lag-1 autocorrelation of the residuals
  double ljung_box_p = 1.0;      ///< p-value of the Ljung-Box test over 10 lags
  std::vector<double> ar;        ///< a_1..a_p of the noise model (empty: white)
  double long_run_factor = 1.0;  ///< 1 + 2 sum rho_l of the noise model
  double effective_n = 0.0;      ///< n / long_run_factor
  double student_df = 0.0;       ///< degrees of freedom of the Student quantile for intervals
  int blocks_won = 0;            ///< parameters whose std comes from the block check
  int rank = 0;
  std::string method;  ///< e.g. "AR(3) noise model of the weighted ln A residuals (...)"
};

/// jacobian: n x p of the weighted model, rows in time order; residuals: the n weighted residuals
/// (sigma^2 = SSE / (n - p)).
/// block_check: step 4 (intervals); false gives steps 1-3 only (the lack-of-fit test, whose power
/// against a misfit localized in time the blocks would absorb).
ArNoiseCovariance arNoiseCovariance(const Eigen::MatrixXd& jacobian,
                                    const Eigen::VectorXd& residuals, bool block_check = true);

/// Steps 1-3 with the noise model fitted separately in up to `blocks` contiguous blocks (at least
/// 150 samples each): a block-diagonal noise covariance, each block's variance and AR(p <= 12,
/// BIC) correlation its own. For the lack-of-fit test, whose covariance
/// must hold where the noise changes along the record (relative noise early, the detector's slow
/// floor noise late) without absorbing a misfit as the cluster sandwich would.
ArNoiseCovariance arNoiseCovarianceLocal(const Eigen::MatrixXd& jacobian,
                                         const Eigen::VectorXd& residuals, int blocks = 4);

/// One-step prediction errors of e under the stationary AR noise model a_1..a_p, in units of the
/// innovation sd (generalized least squares): the first p samples are predicted from the ones
/// before them only (Durbin-Levinson on the model's autocorrelation) and scaled by their larger
/// prediction variance, not dropped, so a misfit that starts with the span (a fast first stage
/// of a decay) keeps its weight; from sample p on, e_i - sum_k a_k e_{i-k}.
std::vector<double> arWhiten(const std::vector<double>& ar, const std::vector<double>& e);

}  // namespace cvg_bench
