// NestedModelFitter implementations for the two experiment modes, all fitting through the
// identification pipeline (identify_pipeline.h) and the model's own trajectory /
// stationary solvers; no equation of the model is written here.
//
// Free decay: fit = buildFreeDecaySystem + estimateFromSystem (LS with the honest lag-2 sandwich);
//   hold-out = fit on the first (1 - holdout_fraction) of the samples, integrate the averaged
//   equations (integrateSlowTrajectory, RK4) from the first measured sample over the whole record,
//   RMS of q_model - q_measured over the held-out last part [units of q].
//   Cheap (ranking) fits: the nested LS problems solved on the columns of the triangular factor
//   of the widest equation-error system (one pass over the record per widening); residual vectors
//   only for fits that are not strict subsets of an earlier one (the linear model, the widest).
// Forced: fit = buildForcedSystem + estimateFromSystem (per-point cluster sandwich); with `mu` in
//   the extensions, mu comes from the output-error fit (refineWithCeres) and z is then refitted by
//   LS at that mu, so sigma stays in equation units; the Wald test of mu uses the Ceres covariance.
//   The residual sum that ranks subsets (NestedFit::rss, scored_residuals) is in output-error
//   units: GLS of (3.4) with block j weighted by A_j^-1 (A_j = dF/dq, two passes) and whitened by
//   one AR(1) along the sweep for all subsets (rho from the whole library's fit,
//   sweep_noise_model.h), so the criterion is the likelihood under that noise model.
//   hold-out = two-fold interleaved (even / odd sweep points): fit one half, equation residuals of
//   the other, RMS over both folds [equation units].
#pragma once

#include <memory>

#include "cvg_bench/core/diagnose/forward_selection.h"
#include "cvg_bench/core/estimate/ceres_refinement.h"
#include "cvg_bench/core/estimate/identification.h"
#include "cvg_bench/core/io/records.h"

namespace cvg_bench {

struct NestedFitterOptions {
  /// Options of every fit (omega, confidence, angular gain, known mu, rank tolerance); the
  /// `model` field is set per fit.
  IdentificationOptions identification;
  /// Options of the output-error fits (mu).
  CeresOptions ceres;
  /// Free decay: fraction of the record (at its end) held out for prediction, in [0.1, 0.6].
  double holdout_fraction = 0.3;
  /// Free decay: RK4 substeps per sampling interval for the hold-out prediction, 1..1000.
  int rk4_substeps = 1;

  /// Every problem with the options, empty when valid.
  std::vector<std::string> validate() const;
};

std::unique_ptr<NestedModelFitter> makeFreeDecayFitter(const SlowRecord& record,
                                                       const NestedFitterOptions& options);
std::unique_ptr<NestedModelFitter> makeForcedFitter(const SweepRecord& record,
                                                    const NestedFitterOptions& options);

}  // namespace cvg_bench
