// Covariance of a ring-down envelope fit (ringdown_fit.h) under the correlated residuals real
// records show (lock-in low-pass, source drift, spectrum-analyser video filter). The tuned
// settings named below are ArNoiseOptions' fields (defaults in brackets).
//
// 1. Detection: the lag-1 autocorrelation of the weighted ln A residuals against its white-noise
//    band +- lag1_band_z / sqrt(n) [2.576: two-sided 1 %] and the Ljung-Box statistic over
//    ljung_box_lags [10] lags at level ljung_box_level [1 %].
// 2. White residuals: the Cramer-Rao covariance sigma^2 (J'J)^-1 (R of the QR of J).
// 3. Correlated residuals: an AR(p) noise model of the residuals (least squares by QR,
//    p <= max_ar_order [12] by BIC), its autocovariance gamma_l from the Yule-Walker recursion, and
//    the sandwich (J'J)^-1 (sum_{i,j} gamma_|i-j| J_i J_j') (J'J)^-1, the lag sum truncated where
//    the model's autocorrelation falls below autocorrelation_cutoff [1e-4]; the variance is scaled
//    so that gamma_0 is the residuals' variance. The effective sample size n / c (c = the long-run
//    variance factor of the model) sets the Student quantile's degrees of freedom.
// 4. Block check (whether or not correlation was detected): the cluster sandwich of the scores
//    J_i' r_i summed over B = min(check_blocks [16], n / check_block_min_samples [10]) contiguous
//    blocks, (J'J)^-1 [B / (B - p) sum_b S_b S_b'] (J'J)^-1, which needs no noise model and holds
//    when the correlation changes along the record (relative noise at the start, filtered additive
//    noise near the floor) or outlasts the AR model. Each parameter keeps the larger of its two
//    standard errors (correlations from step 2/3); where the block one wins, the Student quantile
//    has B - p degrees of freedom.
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
  double ljung_box_p = 1.0;      ///< p-value of the Ljung-Box test (ljung_box_lags lags)
  std::vector<double> ar;        ///< a_1..a_p of the noise model (empty: white)
  double long_run_factor = 1.0;  ///< 1 + 2 sum rho_l of the noise model
  double effective_n = 0.0;      ///< n / long_run_factor
  double student_df = 0.0;       ///< degrees of freedom of the Student quantile for intervals
  int blocks_won = 0;            ///< parameters whose std comes from the block check
  int rank = 0;
  std::string method;  ///< e.g. "AR(3) noise model of the weighted ln A residuals (...)"
};

/// Tuned settings of the steps of the header comment. The defaults are the values of the
/// ring-down validation runs (docs/validation_ringdown.md).
struct ArNoiseOptions {
  /// Step 1: |lag-1 autocorrelation| above lag1_band_z / sqrt(n) counts as correlated
  /// (dimensionless normal quantile; 2.576 is the two-sided 1 % point, the same level as
  /// ljung_box_level). The 1 % level was set by hand with the AR intervals (commit 2cc791c), no
  /// recorded evidence for it over another level.
  double lag1_band_z = 2.576;
  /// Step 1: number of lags of the Ljung-Box statistic (its chi^2 degrees of freedom). Set by hand
  /// (commit 2cc791c), no recorded evidence.
  int ljung_box_lags = 10;
  /// Step 1: a Ljung-Box p-value below this counts as correlated (significance level). Set by hand
  /// (commit 2cc791c), no recorded evidence.
  double ljung_box_level = 0.01;
  /// Step 3: highest AR order tried by BIC (also the cap of each block's order in
  /// arNoiseCovarianceLocal). Set by hand (commit 2cc791c), no recorded evidence.
  int max_ar_order = 12;
  /// Step 3: the AR model is fitted only when n >= ar_min_samples_per_order * max_ar_order +
  /// ar_min_samples_extra (samples; white covariance below). Set by hand (commit 2cc791c), no
  /// recorded evidence.
  int ar_min_samples_per_order = 4;
  /// Step 3: see ar_min_samples_per_order (samples). Set by hand (commit 2cc791c), no recorded
  /// evidence.
  int ar_min_samples_extra = 10;
  /// Step 3 (and each block of arNoiseCovarianceLocal): the lag sum stops at the first lag whose
  /// model autocorrelation is below this in magnitude (dimensionless). Set by hand (commit
  /// 2cc791c), no recorded evidence.
  double autocorrelation_cutoff = 1e-4;
  /// Step 4: most contiguous blocks of the cluster sandwich. Came with the block check (commit
  /// 06f667e, together with smooth-level weights: on tuning base 41000000, 40 clean records, Q
  /// coverage 35/40 -> 38/40, unexplained false alarms 5 -> 2; docs/validation_ringdown.md, method
  /// notes); no other count was compared.
  int check_blocks = 16;
  /// Step 4: fewest samples per block, B = min(check_blocks, n / check_block_min_samples). Set by
  /// hand with the block check (commit 06f667e), no recorded evidence.
  int check_block_min_samples = 10;
  /// Step 4: the check runs only when its Student degrees of freedom B - p are at least this. Set
  /// by hand with the block check (commit 06f667e), no recorded evidence.
  int check_min_df = 4;
  /// arNoiseCovarianceLocal: fewest samples per block, B = min(blocks, n /
  /// local_block_min_samples). Came with the block-local lack-of-fit covariance (commit 52cf922,
  /// one of four noise-model changes that together took the right causes 343 -> 353 of 360 on
  /// tuning bases 41000000 and 42000000, docs/validation_ringdown.md item 4); the value 150 itself
  /// was set by hand, no recorded comparison.
  int local_block_min_samples = 150;
  /// arNoiseCovarianceLocal: a block of m samples tries AR orders up to
  /// min(max_ar_order, m / local_samples_per_ar_order). Set by hand (commit 52cf922), no recorded
  /// evidence.
  int local_samples_per_ar_order = 8;
};

/// jacobian: n x p of the weighted model, rows in time order; residuals: the n weighted residuals
/// (sigma^2 = SSE / (n - p)).
/// block_check: step 4 (intervals); false gives steps 1-3 only (the lack-of-fit test, whose power
/// against a misfit localized in time the blocks would absorb).
ArNoiseCovariance arNoiseCovariance(const Eigen::MatrixXd& jacobian,
                                    const Eigen::VectorXd& residuals, bool block_check = true,
                                    const ArNoiseOptions& options = {});

/// Steps 1-3 with the noise model fitted separately in up to `blocks` contiguous blocks (at least
/// options.local_block_min_samples [150] samples each): a block-diagonal noise covariance, each
/// block's variance and AR(p <= max_ar_order [12], BIC) correlation its own. For the lack-of-fit
/// test, whose covariance must hold where the noise changes along the record (relative noise early,
/// the detector's slow floor noise late) without absorbing a misfit as the cluster sandwich would.
ArNoiseCovariance arNoiseCovarianceLocal(const Eigen::MatrixXd& jacobian,
                                         const Eigen::VectorXd& residuals, int blocks = 4,
                                         const ArNoiseOptions& options = {});

/// One-step prediction errors of e under the stationary AR noise model a_1..a_p, in units of the
/// innovation sd (generalized least squares): the first p samples are predicted from the ones
/// before them only (Durbin-Levinson on the model's autocorrelation) and scaled by their larger
/// prediction variance, not dropped, so a misfit that starts with the span (a fast first stage
/// of a decay) keeps its weight; from sample p on, e_i - sum_k a_k e_{i-k}.
std::vector<double> arWhiten(const std::vector<double>& ar, const std::vector<double>& e);

}  // namespace cvg_bench
