#include "cvg_bench/core/diagnose/candidate_extensions.h"

#include "cvg_bench/core/model/errors.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {
namespace {

const std::vector<CandidateExtension>& allCandidates() {
  static const std::vector<CandidateExtension> c = {
      {"xi", "xi", "cubic stiffness", "1/(s amp^2)",
       "phase-rate (tangential) residual growing with amplitude^2", false},
      {"kappa", "kappa", "quintic stiffness", "1/(s amp^4)",
       "phase-rate (tangential) residual growing with amplitude^4", false},
      {"mu", "mu", "control (actuator) nonlinearity", "1/amp^2",
       "residual concentrated near resonance where the drive acts on large amplitudes", true},
      {"gamma_nl", "gamma_nl", "amplitude-dependent damping", "1/(s amp^2)",
       "amplitude-rate (radial) residual growing with amplitude^2", false},
      {"cm_rate", "cm_rate", "natural-frequency drift during the record", "1/s^2",
       "phase-rate (tangential) residual growing linearly with time", false},
      {"xi_diff", "xi_diff", "unequal cubic stiffness of the two axes", "1/(s amp^2)",
       "amplitude-dependent residual that depends on the pattern angle theta", false},
      {"xi_k", "xi_k", "second cubic invariant (angular-momentum coupling, e.g. Airy precession)",
       "1/(s amp^2)",
       "pattern-angle drift proportional to r k (the ellipse's area) that xi's frequency law "
       "cannot carry",
       false},
  };
  return c;
}

bool applies(const std::string& name, ExperimentMode mode) {
  if (name == "mu") return mode == ExperimentMode::kForced;
  if (name == "cm_rate") return mode == ExperimentMode::kFreeDecay;
  // xi_k is offered for free decay, where the orbit's quadrature k evolves; in forced sweeps it
  // is a term of `identify --model` but not yet validated as a candidate.
  if (name == "xi_k") return mode == ExperimentMode::kFreeDecay;
  return true;
}

}  // namespace

std::vector<CandidateExtension> candidateExtensions(ExperimentMode mode) {
  std::vector<CandidateExtension> out;
  for (const auto& c : allCandidates())
    if (applies(c.name, mode)) out.push_back(c);
  return out;
}

CandidateExtension findCandidateExtension(const std::string& name, ExperimentMode mode) {
  std::string known;
  for (const auto& c : candidateExtensions(mode)) {
    if (c.name == name) return c;
    known += (known.empty() ? "" : ", ") + c.name;
  }
  throw InputError("unknown candidate extension '" + name + "' for " + experimentModeName(mode) +
                   " data (known: " + known + ")");
}

}  // namespace cvg_bench
