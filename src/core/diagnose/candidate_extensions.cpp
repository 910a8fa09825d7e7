#include "cvg_bench/core/diagnose/candidate_extensions.h"

#include <algorithm>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

std::vector<CandidateExtension> candidateExtensions(ExperimentMode mode) {
  std::vector<CandidateExtension> out;
  for (const auto& name : knownModelTermNames())
    for (const auto& c : makeModelTerm(name)->candidates())
      if (mode == ExperimentMode::kFreeDecay ? c.free_decay : c.forced) out.push_back(c);
  std::stable_sort(
      out.begin(), out.end(),
      [](const CandidateExtension& a, const CandidateExtension& b) { return a.rank < b.rank; });
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
