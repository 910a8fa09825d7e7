// The library of candidate model extensions that `explain` tries on top of the linear base, each a
// nested model (the linear model plus one ModelTerm, or mu). Each term declares its own candidacy
// (ModelTerm::candidates: cause, unit, residual signature, modes); this walks the registry.
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/model/model_term.h"

namespace cvg_bench {

/// The candidates that apply to the mode, in the order of their rank:
///   free decay: xi, kappa, gamma_nl, cm_rate, xi_diff, xi_k;
///   forced:     xi, kappa, mu, gamma_nl, xi_diff.
std::vector<CandidateExtension> candidateExtensions(ExperimentMode mode);

/// The candidate with this name (InputError naming the known ones otherwise, or when it does not
/// apply to the mode).
CandidateExtension findCandidateExtension(const std::string& name, ExperimentMode mode);

}  // namespace cvg_bench
