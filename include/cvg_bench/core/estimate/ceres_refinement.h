// Output-error refinement of an equation-error (LS) estimate with Ceres (`--method ceres`).
//
// The equation-error LS of (2.7)-(2.9) / (3.4)-(3.5) puts the noisy measured q inside the regressor
// D(q), which biases it (errors in variables, docs/paper.md item 15) and correlates its equation
// errors (item 10). The output-error fit removes both by comparing measured q with the MODEL's q:
//  - free decay: q_model(t_i) integrates the averaged equations (2.6), 2 q' = D(q) z, by RK4 on the
//    record's time grid from fitted initial slow variables q(t_0) (4 nuisance unknowns);
//  - forced sweep: q_model(omega0_j) is the stationary point of (3.3), 0 = D(q) z - rate_j y(q),
//    solved by Newton from the measured point (stationary_solver.h);
// and minimising sum |q_model - q_measured|^2 over z (and mu when the model spec contains `mu`:
// the control nonlinearity multiplies u~ bilinearly in (3.2), so LS cannot estimate it).
// Covariance: ceres::Covariance (DENSE_SVD, pseudo-inverse on rank deficiency) scaled by
// sigma^2 = 2 cost / (n - rank); Student-t intervals as in (2.11). sigma is in units of q.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cvg_bench/core/estimate/estimate.h"
#include "cvg_bench/core/io/records.h"
#include "cvg_bench/core/model/stationary_solver.h"

namespace cvg_bench {

struct CeresOptions {
  /// Confidence level P0 of the Student-t intervals (2.11), in (0, 1).
  double confidence = 0.95;
  /// Maximum Levenberg-Marquardt iterations, >= 1.
  int max_iterations = 200;
  /// Relative cost change at which Ceres stops, > 0.
  double function_tolerance = 1e-14;
  /// On records of at least likelihood_tolerance_min_samples samples Ceres also stops when a step
  /// lowers n ln(RSS) (n residuals: the scale of the selection criteria and of the likelihood
  /// behind the intervals) by less than this, >= 0: the relative function tolerance becomes
  /// max(function_tolerance, likelihood_tolerance / n). At 1e-4 the optimum left is below ~1e-3
  /// in chi^2, the values within ~0.03 standard errors of it; a misfit model's flat valley
  /// otherwise takes tens of passes over the whole record for changes of 1e-9 of its cost
  /// (docs/benchmarks.md). 0 = function_tolerance alone.
  double likelihood_tolerance = 1e-4;
  /// Samples (free decay) or sweep points from which likelihood_tolerance applies, >= 0. Shorter
  /// records keep the tight tolerances: they cost little, and in a rank-deficient valley the
  /// rank decision depends on how far along it the solver went.
  long likelihood_tolerance_min_samples = 80000;
  /// Relative parameter change at which Ceres stops, > 0.
  double parameter_tolerance = 1e-12;
  /// Max-norm of the gradient at which Ceres stops, > 0.
  double gradient_tolerance = 1e-14;
  /// Free decay: RK4 steps per interval of the record's time grid, 1..1000 (raise it when the
  /// record is sampled coarsely relative to the slow rates).
  int rk4_substeps = 1;
  /// Free decay: a record of at least 4x this many samples is first fitted on every s-th sample
  /// (s ~ record size / coarse_samples, capped so that RK4 on the coarser grid stays accurate), a
  /// cheap start; the fit on the whole record continues from there with the tolerances above, so
  /// the answer is the whole record's optimum either way. 0 = never.
  int coarse_samples = 20000;
  /// Known control nonlinearity mu [1/amplitude^2] used when the model spec has no `mu`; forced
  /// mode only (free decay has no drive).
  double known_mu = 0.0;
  /// Starting value of mu [1/amplitude^2] when mu is estimated and the start estimate lacks it.
  double mu_start = 0.0;
  /// Forced mode: largest fraction of sweep points, in [0, 1), whose stationary point cannot be
  /// solved at the start estimate (fold, no convergence) and are therefore left out (counted in
  /// the notes); more than that is an AnalysisError.
  double max_dropped_fraction = 0.2;
  /// Newton options of the stationary solves (forced mode).
  StationarySolverOptions stationary;
  /// Singular values of the column-normalised Jacobian below this fraction of the largest count as
  /// zero (rank deficiency; the parameters involved are reported as unidentifiable), in (0, 1).
  /// (sqrt of the default min_reciprocal_condition_number, which applies to J'J.)
  double rank_tolerance = 1e-7;
  /// ceres::Covariance min_reciprocal_condition_number (DENSE_SVD truncation), in (0, 1).
  double min_reciprocal_condition_number = 1e-14;
  /// Fill Estimate::derived (section 4 quantities with delta-method CIs) when omega is known and
  /// the fit has full rank.
  bool derive_quantities = true;
  /// Angular gain K of the zero-rate signal Omega = nu / (4 K) (section 4), > 0.
  double angular_gain_k = 0.4;

  /// Every problem with the options, empty when valid.
  std::vector<std::string> validate() const;
};

/// Output-error refinement of a free-decay estimate. start: an estimate of the same model (its
/// `model`, `mode`, `names`, `values`; typically the LS answer). Returns the refined Estimate with
/// method "ceres". InputError for bad input (empty/non-finite/non-increasing record, start not
/// matching its model, invalid options); AnalysisError when Ceres finds no usable solution.
Estimate refineWithCeres(const SlowRecord& record, const Estimate& start,
                         const CeresOptions& options = CeresOptions());

/// The same in two steps: the constructor solves (errors as above); solved() has the values,
/// sigma, rank, dof and notes of the solve but no covariance or intervals (enough to rank a
/// model or to predict with it); finish() adds the covariance, intervals, identifiability and
/// derived quantities and returns what refineWithCeres returns. The record must outlive the
/// object and its copies (they share the solved state).
class FreeDecayRefinement {
 public:
  FreeDecayRefinement(const SlowRecord& record, const Estimate& start,
                      const CeresOptions& options = CeresOptions());
  const Estimate& solved() const;
  Estimate finish() const;

 private:
  struct State;
  std::shared_ptr<const State> state_;
};

/// Output-error refinement of a forced-sweep estimate (stationary points of (3.3)); omega from
/// start.omega_rad_s, else record.omega_rad_s (InputError when neither is > 0). Estimates mu
/// jointly when start.model contains `mu`.
Estimate refineWithCeres(const SweepRecord& record, const Estimate& start,
                         const CeresOptions& options = CeresOptions());

}  // namespace cvg_bench
