// The library of candidate model extensions that `explain` tries on top of the linear base, each a
// nested model (the linear model plus one ModelTerm, or mu), with the physical cause in words and
// the residual signature it removes. The terms themselves live in their ModelTerm files; this
// list only says which ones are candidates in which mode and how to talk about them.
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/model/model_term.h"

namespace cvg_bench {

struct CandidateExtension {
  std::string name;       ///< canonical extension name (ResonatorModel spec part): "xi", "mu", ...
  std::string parameter;  ///< the parameter it adds (same as name for all current candidates)
  std::string cause;      ///< the physical cause, a short noun phrase ("cubic stiffness")
  std::string unit;       ///< unit of the parameter in regression units, e.g. "1/(s amp^2)"
  /// What its absence leaves in the residuals (the signature it removes), in words.
  std::string signature;
  /// Estimated by output error (Ceres): mu multiplies u~ bilinearly (3.2), LS cannot fit it.
  bool needs_output_error = false;
};

/// The candidates that apply to the mode, in a fixed order:
///   free decay: xi, kappa, gamma_nl, cm_rate, xi_diff, xi_k;
///   forced:     xi, kappa, mu, gamma_nl, xi_diff.
std::vector<CandidateExtension> candidateExtensions(ExperimentMode mode);

/// The candidate with this name (InputError naming the known ones otherwise, or when it does not
/// apply to the mode).
CandidateExtension findCandidateExtension(const std::string& name, ExperimentMode mode);

}  // namespace cvg_bench
