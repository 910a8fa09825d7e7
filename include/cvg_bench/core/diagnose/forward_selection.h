// Forward selection of model extensions with the gain measured at every step (issue 5).
//
// Start from the linear model; at each step fit every remaining candidate as a nested model
// (current + candidate) through a NestedModelFitter (the identification API, never a second
// estimator), and measure
//   sigma_ratio    sigma-hat(current) / sigma-hat(extended)                       (2.10)
//   f_statistic,   Wald test of the added parameters with the honest covariance
//   p_value        (model_diagnosis.h; the RSS F-test is invalid for correlated equation errors)
//   delta_bic      n ln(RSS_1/RSS_0) + dk ln n (reported only)
//   holdout_ratio  hold-out RMS of the current model / that of the extended one (fit on part of
//                  the data, predict the rest; see the fitter)
// Accept the candidate with the smallest p-value among those with holdout_ratio >
// min_holdout_ratio and sigma_ratio > 1 (the extended fit must fit better: a nested output-error
// fit that lands in a worse local minimum is not a discovery) when p < alpha / m (Bonferroni over
// the m candidates tried at the step); stop when none qualifies. Finally a backward check drops an
// accepted term whose Wald p-value in the final model exceeds alpha / (number of accepted terms)
// (e.g. xi accepted first, then made redundant by kappa). On clean data the family-wise
// false-discovery rate is then <= alpha per step, as long as the honest covariance is honest
// (checked by test/core/hidden_effect_test.cpp and scripts/validate_explain.py).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "cvg_bench/core/diagnose/candidate_extensions.h"
#include "cvg_bench/core/estimate/estimate.h"
#include "cvg_bench/core/diagnose/model_diagnosis.h"
#include "cvg_bench/core/diagnose/residual_signature.h"

namespace cvg_bench {

/// A model fitted to the whole record or sweep.
struct NestedFit {
  std::vector<std::string> extensions;  ///< extension names in the order added
  std::string model;                    ///< canonical spec, e.g. "linear+xi"
  Estimate estimate;                    ///< the identify output of this model
  double sigma = 0.0;                   ///< sigma-hat (2.10) in equation units
  double rss = 0.0;                     ///< residual sum of squares of the equations
  long n_equations = 0;
  Eigen::VectorXd residuals;  ///< equation residuals y - D z (4 per block)
};

/// Mode-specific fitting through the identification API (nested_model_fitters.h).
class NestedModelFitter {
 public:
  virtual ~NestedModelFitter() = default;
  /// The linear base plus these extensions, fitted to all the data.
  virtual NestedFit fit(const std::vector<std::string>& extensions) const = 0;
  /// RMS prediction error on the held-out part after fitting the rest (units of q for free
  /// decay, equation units for forced sweeps).
  virtual double holdoutRms(const std::vector<std::string>& extensions) const = 0;
  /// How the hold-out is made, in words (for the report).
  virtual std::string holdoutDescription() const = 0;
  /// The fit's equation residuals per block with the slow state and abscissa of each block.
  virtual std::vector<BlockResidual> blocks(const NestedFit& fit) const = 0;
  /// Residuals for the adequacy (lack-of-fit) test, independent under an adequate model: free
  /// decay the output-error trajectory residuals q_measured - q_model per sample (initial state
  /// refitted), forced the per-point equation residuals (= blocks()).
  virtual std::vector<BlockResidual> adequacyResiduals(const NestedFit& fit) const = 0;
};

struct SelectionOptions {
  /// Family-wise significance level per step, in (0, 0.5); each of the m candidates tried at a
  /// step must reach p < alpha / m (Bonferroni).
  double alpha = 0.01;
  /// A candidate must predict the held-out data better than the current model by this factor
  /// (holdout_ratio > min_holdout_ratio), >= 0.
  double min_holdout_ratio = 1.0;
  /// Largest number of extensions accepted, >= 1.
  int max_steps = 4;
  /// Drop accepted terms that are no longer significant in the final model.
  bool backward_check = true;

  /// Every problem with the options, empty when valid.
  std::vector<std::string> validate() const;
};

/// One candidate tried at one step.
struct SelectionStep {
  std::string added;         ///< candidate name
  std::string model;         ///< canonical spec of the extended model
  double sigma = 0.0;        ///< sigma-hat of the extended model
  double sigma_ratio = 0.0;  ///< sigma(current) / sigma(extended)
  WaldTestResult wald;       ///< test of the added parameter(s)
  double delta_bic = 0.0;
  double holdout_ratio = 0.0;  ///< holdout RMS(current) / holdout RMS(extended)
  double threshold = 0.0;      ///< alpha / m of this step
  bool accepted = false;
  NestedFit fit;  ///< the extended model's fit
};

struct SelectionResult {
  NestedFit baseline;                     ///< the linear model
  std::vector<SelectionStep> steps;       ///< accepted steps in order
  std::vector<SelectionStep> last_round;  ///< candidates of the round that stopped the selection
  std::vector<std::string> selected;      ///< accepted extensions (after the backward check)
  std::vector<std::string> dropped;       ///< accepted then dropped by the backward check
  NestedFit final_fit;                    ///< the model with `selected`
  std::string holdout_description;
};

/// Runs the selection over `candidates` (see the header comment). Candidates whose fit fails with
/// an AnalysisError (e.g. rank deficiency) or InputError are skipped with a note in `notes`.
SelectionResult forwardSelect(const NestedModelFitter& fitter,
                              const std::vector<CandidateExtension>& candidates,
                              const SelectionOptions& options, std::vector<std::string>* notes);

}  // namespace cvg_bench
