// Selection of model extensions for `explain`: best subset up to max_terms candidates,
// ranked on the cheap equation-error LS fit, decided on the refined (output-error) fits of the
// finalists, confirmed on a hold-out (subset_selection.cpp has the procedure).
//
// Criterion of a subset S with k_S added terms, from residuals r (N values) of its fit:
//   IC(S) = n_eff ln(RSS_S / N) + k_S * penalty,   n_eff = N / c,
//   penalty = max(ln n_eff, chi^2_1 quantile at 1 - alpha / m)      (m = candidates)
// c = 1 + 2 sum_l rho_l is the long-run variance factor of the residuals (long_run_variance.h):
// correlated noise (AR(1) on q, the demodulator's filter, the lag-2 structure of (2.8)) makes
// n ln(RSS_0 / RSS_1) ~ c chi^2 under a null term, so n_eff ln(...) ~ chi^2 again. The penalty is
// BIC's ln n_eff, but never below the Bonferroni chi^2 quantile so that clean records select a null
// term with probability <= alpha. Every step records the gain as before:
//   sigma_ratio    sigma-hat(previous) / sigma-hat(extended)                       (2.10)
//   f_statistic,   Wald test of the added parameter with the honest covariance
//   p_value        (model_diagnosis.h)
//   delta_bic      n ln(RSS_1/RSS_0) + dk ln n (reported only)
//   holdout_ratio  hold-out RMS of the previous model / that of the extended one
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "cvg_bench/core/diagnose/candidate_extensions.h"
#include "cvg_bench/core/diagnose/model_diagnosis.h"
#include "cvg_bench/core/diagnose/residual_signature.h"
#include "cvg_bench/core/estimate/estimate.h"

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
  /// The residuals behind rss when they are not `residuals` (forced sweeps: whitened output
  /// errors, nested_model_fitters.h); the selection's c is computed from these.
  Eigen::VectorXd scored_residuals;
  /// The linear part's z of that scoring fit, when it differs from the estimate's (forced: the
  /// output-error GLS; the adequacy residuals are taken there).
  Eigen::VectorXd scored_values;
  /// Set when the estimate's covariance and intervals were deferred (a refined fit that may only
  /// be ranked): returns the complete estimate (the same sigma, rss and values).
  std::function<Estimate()> finish;
};

/// Mode-specific fitting through the identification API (nested_model_fitters.h).
class NestedModelFitter {
 public:
  virtual ~NestedModelFitter() = default;
  /// The linear base plus these extensions, fitted to all the data.
  virtual NestedFit fit(const std::vector<std::string>& extensions) const = 0;
  /// fit() started near `near`, a refined fit of a nested model (its values where the models
  /// share parameters): the same optimum, found in fewer iterations. Default: fit().
  virtual NestedFit fitNear(const std::vector<std::string>& extensions,
                            const NestedFit& near) const {
    (void)near;
    return fit(extensions);
  }
  /// The cheap fit used to rank subsets: equation-error LS (free decay), the same as fit() where
  /// there is nothing cheaper (forced sweeps).
  virtual NestedFit fitEquationError(const std::vector<std::string>& extensions) const {
    return fit(extensions);
  }
  /// True when fit() returns output-error (trajectory) residual sums in units of q, i.e. a
  /// different scale than fitEquationError() (free decay).
  virtual bool refinesByOutputError() const { return false; }
  /// Known correlation rho_1, rho_2, ... of the measurement noise between neighbouring samples
  /// (a demodulated record's `noise_correlation`); empty when unknown.
  virtual std::vector<double> knownNoiseCorrelation() const { return {}; }
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
  /// Family-wise false-selection level, in (0, 0.5): sets the criterion's penalty floor (chi^2_1
  /// quantile at 1 - alpha / m, m candidates).
  double alpha = 0.01;
  /// A candidate must predict the held-out data better than the current model by this factor
  /// (holdout_ratio > min_holdout_ratio), >= 0.
  double min_holdout_ratio = 1.0;
  /// Largest number of extensions in a subset, 1..4.
  int max_steps = 3;
  /// Subsets (besides the linear model) refined by the expensive fit, best first by the LS
  /// criterion, 1..20.
  int finalists = 4;
  /// A finalist whose output-error fit failed is replaced by further subsets in LS order, at most
  /// max_tried_per_finalist * finalists subsets tried in all, >= 1. Set by hand (commit d229321,
  /// which added the replacement for the Foucault record), no recorded evidence for the factor.
  int max_tried_per_finalist = 2;
  /// Drop a term of the chosen subset when the subset without it has a better refined criterion.
  bool backward_check = true;
  /// Refined fits and hold-outs of one selection step run this many at a time, 0..64 (0: the
  /// machine's cores); the selection and every number are the same for any value.
  int threads = 0;

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
  double holdout_ratio = 0.0;    ///< holdout RMS(current) / holdout RMS(extended)
  double delta_criterion = 0.0;  ///< IC(extended) - IC(current) (negative favours the extension)
  double threshold = 0.0;        ///< alpha / m of this step
  bool accepted = false;
  NestedFit fit;  ///< the extended model's fit
};

/// One subset of candidates with its criteria.
struct SubsetScore {
  std::vector<std::string> terms;  ///< extension names, candidate order
  std::string model;               ///< canonical spec
  double criterion_ls = 0.0;       ///< IC of the cheap (equation-error) fit, lower is better
  bool refined = false;            ///< fitted by the expensive fit (a finalist)
  double criterion = 0.0;          ///< IC of the refined fit (= criterion_ls when not refined)
  double sigma = 0.0;              ///< sigma-hat of the refined (else the cheap) fit
  double holdout_ratio = 0.0;      ///< holdout RMS(linear) / holdout RMS(this); 0 = not computed
};

struct SelectionResult {
  NestedFit baseline;                     ///< the linear model
  std::vector<SelectionStep> steps;       ///< accepted steps in order
  std::vector<SelectionStep> last_round;  ///< candidates of the round that stopped the selection
  std::vector<std::string> selected;      ///< accepted extensions (after the backward check)
  std::vector<std::string> dropped;       ///< in the best-criterion subset, dropped by the
                                          ///< hold-out confirmation or the backward check
  std::vector<SubsetScore> subsets;       ///< every subset fitted, best cheap criterion first
  SubsetScore chosen;                     ///< the selected subset
  SubsetScore runner_up;                  ///< the best refined subset not chosen
  double runner_up_delta = 0.0;           ///< IC(runner-up) - IC(chosen) (> 0: chosen better)
  double correlation_factor_ls = 1.0;     ///< c of the equation-error residuals
  double correlation_factor = 1.0;        ///< c of the refined fit's residuals
  std::string criterion_description;      ///< the criterion in words
  NestedFit final_fit;                    ///< the model with `selected`
  std::string holdout_description;
};

/// Runs the selection over `candidates` (see the header comment and subset_selection.cpp). Subsets
/// whose fit fails with an AnalysisError (e.g. rank deficiency) or InputError are skipped with a
/// note in `notes`.
SelectionResult selectExtensions(const NestedModelFitter& fitter,
                                 const std::vector<CandidateExtension>& candidates,
                                 const SelectionOptions& options, std::vector<std::string>* notes);

}  // namespace cvg_bench
