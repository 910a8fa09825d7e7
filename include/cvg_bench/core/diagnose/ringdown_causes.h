// What a single-channel ring-down shows besides Q: the causes one envelope can reveal, found by
// fitting the extensions of ringdown_models.h against the straight ln A decay.
//  - gamma_nl: damping growing with A^2 (gas, thermoelastic); gamma_a: growing with A (clamping);
//  - beat: two close modes in one channel (split frequency and both decay rates);
//  - two_stage: two decays without beating;
//  - noise_floor, drop_outs: from the segmentation;
//  - unexplained: systematic structure no physical law removes (a rate that rises and falls, or an
//    amplitude law with the wrong sign: detection loss, the mode drifting out of the band).
// Test: likelihood ratio of the weighted fits with the sample count divided by the HAC variance
// inflation of the extended fit (correlated residuals carry fewer independent samples), level
// alpha Bonferroni over the candidates (the beat also over the searched frequencies); every fitted
// damping must be positive and the amplitude law's coefficient positive (sign check), else the
// extension is not accepted. The final model's lack of fit: HAC Wald test of Legendre polynomials
// P2..P5 in time added to its residuals.
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/estimate/ringdown_fit.h"

namespace cvg_bench {

struct RingdownExplainOptions {
  /// Family-wise level of the extension tests and of the lack-of-fit test, (0, 0.2].
  double alpha = 0.001;
  /// Candidate extensions tried (ringdownExtensionNames() by default).
  std::vector<std::string> candidates = {"gamma_nl", "gamma_a", "beat", "two_stage"};
  RingdownFitOptions fit;
  RingdownSegmentationOptions segmentation;
  std::vector<std::string> validate() const;
};

struct RingdownStep {
  std::string added;
  double sigma = 0.0, sigma_ratio = 1.0;
  double lr_statistic = 0.0;  ///< n_eff ln(SSE_base / SSE_ext)
  double threshold = 0.0;     ///< its critical value
  double n_eff = 0.0;
  double p_value = 1.0;
  bool significant = false, physical = false, accepted = false;
  std::string note;  ///< why not accepted / the sign check
};

struct RingdownExplanation {
  RingdownSegment segment;
  RingdownFit baseline, final_fit;
  std::vector<RingdownStep> steps;
  std::vector<std::string> selected;  ///< accepted extensions (at most one)
  std::vector<std::string> causes;    ///< named findings (see the header comment)
  bool unexplained = false;
  bool adequate = false;  ///< final model fits, every damping positive
  std::string lack_of_fit_test;
  double lack_of_fit_p = 1.0;
  std::string cause;  ///< sentences a bench engineer can act on
};

RingdownExplanation explainRingdown(const RingdownEnvelope& env,
                                    const RingdownExplainOptions& options = {});

/// Lack of fit of a fitted model: HAC Wald test of Legendre P2..P5(t') added to its residuals.
/// Returns the p-value.
double ringdownLackOfFitP(const RingdownFit& fit);

}  // namespace cvg_bench
