// Parameter identification by equation-error least squares: the entry points the tool, the nodes,
// the explain report and the Ceres refinement call.
//
// Free decay (section 2): (2.6) 2 q' = D(q) z integrated over [t_{i-1}, t_{i+1}] gives, with the
// factor 1/2 of (2.7) kept (docs/paper.md item 12),
//   y_i = 2 (q(t_{i+1}) - q(t_{i-1})) = (integral of D(q(t)) dt) z,   i = 1..N-1,      (2.7)-(2.8)
// the integral by Simpson's rule on uniform times, by the trapezoid rule otherwise; n = 4(N-1)
// equations (item 8). Forced sweep (section 3): the stationary equations (3.3)
//   y_j = rate_j (p1, -q1, p2, -q2)_j = D(q_j) z,   rate_j = (omega0_j^2 - omega^2) / omega0_j
//   (3.4)
// (exact detuning rate, item 7), j = 1..N, N >= 4. D(q) comes only from ResonatorModel::regressor.
//
// Both are solved by QR + SVD with numerical rank (least_squares_solver.h); sigma-hat (2.10).
// Intervals: `parameters` holds HONEST intervals, `parameters_paper` the paper's (2.11):
//  - free decay: the equation errors are correlated (y_i and y_{i+2} share q_{i+1} with opposite
//    signs; the noisy q also enters D_i), so (2.11) is ~4x too wide (item 10). The honest
//    covariance is the sandwich C D' Omega D C, C = (D'D)^-1, with Omega's block structure known
//    to end at lag 2 blocks (Newey-West-like with uniform weights up to lag 2, estimated from the
//    residuals; within each record only), scaled by n / (n - k); normal quantile.
//  - forced: errors are independent between sweep points but heteroscedastic and correlated within
//    a point's 4 equations (the noisy q enters both y and D): a block (cluster) sandwich with the
//    small-sample factor G/(G-1) (n-1)/(n-k), Student-t with G - 1 dof (G = number of points).
//    Errors in variables still bias LS ~ sigma_q^2 (item 15): use --method ceres for noisy sweeps.
// Rank deficiency (identifiability.h) is reported in the Estimate (rank, unidentifiable,
// identifiability_note, combinations), not thrown; callers decide (the tool exits 1).
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/estimate/estimate.h"
#include "cvg_bench/core/io/records.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

struct IdentificationOptions {
  /// Model spec of ResonatorModel: `linear` or `+`-joined extensions (`xi`, `xi+kappa`, ...).
  /// `mu` (forced) is not linear in z: LS refuses it (InputError pointing to --method ceres).
  std::string model = "linear";
  /// "ls" (batch QR) or "rls" (block recursive least squares (2.12), corrected pairing).
  std::string method = "ls";
  /// Confidence level P0 of the intervals (2.11), in (0, 1).
  double confidence = 0.95;
  /// Natural frequency omega [rad/s]; > 0 overrides the record's. Forced mode needs it (from here
  /// or the record); free decay uses it only for the derived quantities (Q).
  double omega_rad_s = 0.0;
  /// Angular gain K of the zero-rate signal Omega = nu / (4 K) (section 4), > 0 (0.4 for a ring).
  double angular_gain_k = 0.4;
  /// Known control nonlinearity mu [1/amplitude^2] of (3.1)-(3.2), forced mode; finite.
  double mu = 0.0;
  /// Relative singular-value tolerance of the numerical rank (column-equilibrated matrix), (0, 1).
  double rank_tolerance = 1e-9;
  /// Free decay: time steps within this relative spread of their mean count as uniform (Simpson),
  /// otherwise the trapezoid rule is used; in (0, 1).
  double uniform_time_tolerance = 1e-6;
  /// RLS: number of blocks m of the initial batch solve; 0 = automatic (max(2k, 8) blocks).
  int rls_init_blocks = 0;
  /// RLS forgetting factor in (0, 1]; 1 = the paper's (2.12) (equals the batch estimate).
  double rls_forgetting = 1.0;
  /// Fill Estimate::derived (section 4 quantities with delta-method CIs) when omega is known.
  bool derive_quantities = true;
  /// Free decay, LS: number of residual correlations (lags 1..this, >= 2) the AR(1) noise model on
  /// q is fitted to when the lag-1 test rejects independence (interval_method_id eiv_ar1). Set by
  /// hand (commit efb8987), no recorded comparison of lag counts; the eiv_ar1 intervals it gives
  /// covered 0.954 (60 runs of cov_fd_ar1, noise AR(1) 0.9; docs/validation.md).
  int residual_ar1_lags = 12;

  /// Every problem with the options, empty when valid.
  std::vector<std::string> validate() const;
};

/// Free-decay identification of one record (t_s from 0 or any origin: time-varying terms use the
/// time since the record's first sample). InputError for bad input (fewer than 3 samples + enough
/// equations for the model, NaN/Inf, non-increasing times, constant data, bad options).
Estimate identifyFreeDecay(const SlowRecord& record, const IdentificationOptions& options);
/// Several records stacked into one regression (e.g. runs at different pattern angles,
/// docs/paper.md item 11); each record keeps its own time origin, integration rule and lag
/// structure, and no equation joins two records. InputError also when one record is given twice,
/// or, without options.omega_rad_s, when the records' natural frequencies differ by more than
/// 100 ppm (unknown in all is allowed).
Estimate identifyFreeDecay(const std::vector<SlowRecord>& records,
                           const IdentificationOptions& options);

/// Forced-sweep identification (3.4)-(3.5). InputError for fewer than 4 points, NaN/Inf, omega0 <=
/// 0, unknown omega, a `mu` model (use refineWithCeres), bad options.
Estimate identifyForced(const SweepRecord& record, const IdentificationOptions& options);
Estimate identifyForced(const std::vector<SweepRecord>& records,
                        const IdentificationOptions& options);

/// The stacked regression y = D z + e with what each equation belongs to (for residual analysis).
/// Row r is component r % 4 (q1, p1, q2, p2 equation) of block r / 4.
struct StackedSystem {
  ExperimentMode mode = ExperimentMode::kFreeDecay;
  std::string model;               ///< canonical spec
  std::vector<std::string> names;  ///< parameter names, column order
  Eigen::MatrixXd d;               ///< n x k
  Eigen::VectorXd y;               ///< n
  /// Per block: free decay the centre time t_i [s] (from the record's first sample); forced the
  /// drive frequency omega0_j [rad/s].
  std::vector<double> abscissa;
  std::vector<double> detuning_rad_s;  ///< forced: lambda_j = omega0_j - omega; free decay: empty
  std::vector<double> amplitude;       ///< per block: |q| at the centre sample / sweep point
  std::vector<int> record_index;       ///< per block: which input record
  bool simpson = true;                 ///< free decay: Simpson (uniform) or trapezoid rule
  int numBlocks() const { return static_cast<int>(abscissa.size()); }
};

/// The stacked free-decay system (2.8) (stored densely: use for moderate sizes).
StackedSystem buildFreeDecaySystem(const std::vector<SlowRecord>& records,
                                   const IdentificationOptions& options);
/// The stacked forced system (3.5); omega from options, else the records'.
StackedSystem buildForcedSystem(const std::vector<SweepRecord>& records,
                                const IdentificationOptions& options);
/// y - D z, one entry per equation.
Eigen::VectorXd equationResiduals(const StackedSystem& system, const Eigen::VectorXd& z);
/// LS estimate (with honest and paper intervals, identifiability) of an already stacked system,
/// e.g. a nested model's columns: D restricted to a subset of columns. free decay systems use the
/// lag-2 sandwich, forced ones the per-point sandwich.
Estimate estimateFromSystem(const StackedSystem& system, const IdentificationOptions& options);

}  // namespace cvg_bench
