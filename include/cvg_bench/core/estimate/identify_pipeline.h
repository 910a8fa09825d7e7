// The one identification pipeline: every caller (cvg_ident identify, the identifier node's
// `identify` service, explain's nested-model fitters) asks for a method and gets the same chain.
//
//   kLs     batch equation-error least squares: free decay (2.7)-(2.8), forced sweep (3.4)-(3.5);
//   kRls    the block recursive least squares (2.12) over the same blocks (corrected pairing);
//   kCeres  LS start, then the output-error refinement (ceres_refinement.h), which removes the
//           errors-in-variables bias of the equation-error fit (docs/paper.md item 15).
//
// The control nonlinearity mu of (3.1)-(3.2) multiplies u~ bilinearly, so no linear regression
// estimates it. When the model estimates it (ResonatorModel::estimatesMu, forced mode only), the
// pipeline solves the linear part by LS at mu = identification.mu (the start value) and lets Ceres
// estimate z and mu jointly; any other method is an InputError naming the way out.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "cvg_bench/core/estimate/ceres_refinement.h"
#include "cvg_bench/core/estimate/estimate.h"
#include "cvg_bench/core/estimate/identification.h"
#include "cvg_bench/core/io/records.h"

namespace cvg_bench {

enum class Method { kLs, kRls, kCeres };

/// "ls" / "rls" / "ceres" <-> Method; InputError for other names.
Method parseMethod(const std::string& name);
std::string methodName(Method method);

/// What to do when the Ceres refinement finds no usable solution (AnalysisError).
enum class CeresFailure {
  kThrow,     ///< pass the AnalysisError on (the tool reports it)
  kKeepStart  ///< return the LS start with a note saying why (explain's nested fits)
};

struct PipelineOptions {
  Method method = Method::kLs;
  /// Model, confidence, omega, angular gain, mu, rank tolerance, RLS settings of the regression.
  /// Its `method` field is set by the pipeline from `method`. `mu` is the known control
  /// nonlinearity when the model does not estimate mu, else the start value of the Ceres fit.
  IdentificationOptions identification;
  /// Solver settings of the output-error refinement (kCeres). Its confidence, angular gain,
  /// known_mu and mu_start are taken from `identification`, so the two stages agree.
  CeresOptions ceres;
  CeresFailure on_ceres_failure = CeresFailure::kThrow;
  /// Free decay, kCeres: values that replace the LS answer's in the refinement's start (e.g. a
  /// nested model's refined fit: explain's one-term extensions), the other parameters keeping
  /// their LS values; the start is then near the optimum and the coarse start is skipped.
  std::map<std::string, double> ceres_start;
  /// With ceres_start: the initial slow variables q(t0) to start from (that fit's
  /// Estimate::initial_slow_state); empty = the first measured sample.
  Eigen::VectorXd ceres_start_state;

  /// Every problem with the options (of both stages), empty when valid.
  std::vector<std::string> validate() const;
};

/// Free-decay identification of one record. InputError for bad input or options; AnalysisError
/// when Ceres finds no usable solution and on_ceres_failure is kThrow.
Estimate identify(const SlowRecord& record, const PipelineOptions& options);
/// Several free decays of one resonator in one fit (e.g. decays started at several pattern angles,
/// which bound the anisotropies' two axes better than one: docs/validation_drift.md), by the
/// stacked regression identifyFreeDecay(std::vector); one record is identify(record). InputError
/// for method kCeres with several records (the output-error fit integrates one trajectory).
Estimate identify(const std::vector<SlowRecord>& records, const PipelineOptions& options);
/// The same with the free-decay refinement's covariance deferred (explain ranks many refined fits
/// and reports few): `estimate` is FreeDecayRefinement::solved() (values, sigma, rank, dof; no
/// intervals) and `finish` returns what identify() returns; with another method, or when the
/// refinement failed and on_ceres_failure keeps the start, `estimate` is identify()'s answer and
/// `finish` is empty. The record must outlive `finish`.
struct DeferredEstimate {
  Estimate estimate;
  std::function<Estimate()> finish;
};
DeferredEstimate identifyDeferred(const SlowRecord& record, const PipelineOptions& options);
/// Forced-sweep identification of one sweep record; errors as above.
Estimate identify(const SweepRecord& record, const PipelineOptions& options);

}  // namespace cvg_bench
