// `explain`: what the linear model gets wrong, the physical cause, the extended model and the gain
// (the paper's own story: the linear model leaves a systematic error in the forced
// response, Fig. 2; cubic stiffness removes it, Fig. 3, residual std 0.295 -> 0.0926).
//
// Steps: (1) fit the linear baseline and read its residual signature (residual_signature.h);
// (2) best-subset selection over the candidate extensions (forward_selection.h) with the gain of
// every step and the runner-up; (3) lack-of-fit test of the final model, its residuals whitened
// by the noise model of residual_noise_model.h (known demodulator correlation, else AR(1) fitted
// after the smooth part is removed); in free decay also the low-frequency GLS test of
// low_frequency_misfit.h, Bonferroni with the runs test:
//   forced sweep: Wald-Wolfowitz runs test of the per-point residuals ordered by drive frequency
//     (points do not share samples, so they are independent under an adequate model), on the
//     radial and tangential projections and the 4 components, Bonferroni over the 6 sequences;
//   free decay: the same runs test on the output-error (trajectory) residuals q_measured - q_model
//     (z of the output-error fit, initial state refitted): docs/paper.md item 10, the equation
//     errors of (2.8) share samples, so a whiteness test on them flags clean data; the trajectory
//     residuals are the measurement noise itself under an adequate model. Decimated to ~200
//     values per sequence;
// (4) the verdict in words: cause, parameter with CI, gain; `unexplained` when the final model
// still fails the lack-of-fit test (forced sweeps: or keeps a significant residual signature).
// The ROS identifier node's Explain service and the tool's `explain` subcommand both call
// explainFreeDecay / explainForced.
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/diagnose/forward_selection.h"
#include "cvg_bench/core/diagnose/nested_model_fitters.h"
#include "cvg_bench/core/diagnose/orbit_reading.h"
#include "cvg_bench/core/diagnose/residual_noise_model.h"
#include "cvg_bench/core/diagnose/residual_signature.h"
#include "cvg_bench/core/io/records.h"

namespace cvg_bench {

struct ExplainOptions {
  /// Fitting options (omega [rad/s], confidence, angular gain K, known mu, hold-out fraction...).
  NestedFitterOptions fitting;
  /// Selection thresholds (alpha per step with Bonferroni, hold-out requirement).
  SelectionOptions selection;
  /// Candidate extension names; empty = every candidate of the mode (candidate_extensions.h).
  std::vector<std::string> candidates;
  /// Level of the lack-of-fit test and of the residual signature (Bonferroni inside), in (0, 0.5).
  double lack_of_fit_alpha = 0.01;
  /// Free decay: every stride-th block is used by the signature correlations, >= 3 (item 10).
  int signature_stride = 3;
  /// Bins of the signature plots, 2..100.
  int signature_bins = 10;

  /// Every problem with the options, empty when valid.
  std::vector<std::string> validate() const;
};

struct LackOfFit {
  std::string test;         ///< what was tested, in words
  double p_value = 1.0;     ///< Bonferroni-combined p-value (residuals whitened by the noise model)
  std::string worst;        ///< the sequence with the fewest runs relative to expectation
  std::string noise_model;  ///< the whitening noise model, in words
  double p_value_unwhitened = 1.0;     ///< the same test on the raw residuals (for comparison)
  double runs_p_value = 1.0;           ///< the whitened runs test alone
  double low_frequency_p_value = 1.0;  ///< free decay: low_frequency_misfit.h (1 in forced mode)
  std::string low_frequency;           ///< that test's worst sequence, in words
  double signature_p_value =
      1.0;  ///< smallest final-signature p-value times the entries (Bonferroni)
};

struct Explanation {
  ExperimentMode mode = ExperimentMode::kFreeDecay;
  SelectionResult selection;                   ///< baseline, steps, last round, selected, final fit
  std::vector<BlockResidual> baseline_blocks;  ///< residual blocks of the linear model
  std::vector<BlockResidual> final_blocks;     ///< of the final model
  ResidualSignature baseline_signature;
  ResidualSignature final_signature;  ///< of the whitened final residuals
  ResidualNoiseModel noise_model;     ///< under which the adequacy is tested
  LackOfFit lack_of_fit;              ///< of the final model
  bool unexplained = false;           ///< structure remains that no accepted extension removes
  /// The final estimate has full rank: the record determines the model's parameters. False: its
  /// parameters, Q and drift are not estimates (the verdict says so; cvg_ident exits 1).
  bool determined = true;
  std::string cause;               ///< the verdict in words
  std::vector<std::string> notes;  ///< provenance and skipped candidates
  /// Free decay: what the record shows before any model, beside the final model's drift
  /// prediction (orbit_reading.h); not valid in forced mode.
  OrbitReading measured;
  const Estimate& finalEstimate() const { return selection.final_fit.estimate; }
};

/// Explains a free-decay record (validated by the identification; InputError for bad input,
/// bad options or unknown candidates; AnalysisError when even the linear model cannot be fitted).
Explanation explainFreeDecay(const SlowRecord& record, const ExplainOptions& options);
/// Explains a forced sweep (omega from the options or the record).
Explanation explainForced(const SweepRecord& record, const ExplainOptions& options);

}  // namespace cvg_bench
