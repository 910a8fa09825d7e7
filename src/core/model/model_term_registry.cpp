#include <functional>
#include <map>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/model/model_terms.h"

namespace cvg_bench {
namespace {

const std::vector<std::pair<std::string, std::function<ModelTermPtr()>>>& registry() {
  static const std::vector<std::pair<std::string, std::function<ModelTermPtr()>>> r = {
      {"linear", makeLinearDefectTerm},       {"controls", makeControlTerm},
      {"xi", makeCubicStiffnessTerm},         {"kappa", makeQuinticStiffnessTerm},
      {"gamma_nl", makeNonlinearDampingTerm}, {"cm_rate", makeFrequencyDriftTerm},
      {"xi_diff", makeAxisCubicMismatchTerm}, {"xi_k", makeAngularMomentumCubicTerm},
  };
  return r;
}

}  // namespace

ModelTermPtr makeModelTerm(const std::string& name) {
  for (const auto& entry : registry()) {
    if (entry.first == name) return entry.second();
  }
  std::string known;
  for (const auto& entry : registry()) known += (known.empty() ? "" : ", ") + entry.first;
  throw InputError("unknown model term '" + name + "' (known: " + known + ")");
}

std::vector<std::string> knownModelTermNames() {
  std::vector<std::string> names;
  for (const auto& entry : registry()) names.push_back(entry.first);
  return names;
}

bool isAmplitudeLawParameter(const std::string& parameter) {
  for (const auto& entry : registry()) {
    const ModelTermPtr t = entry.second();
    if (!t->isAmplitudeLaw()) continue;
    for (const auto& p : t->parameterNames())
      if (p == parameter) return true;
  }
  return false;
}

bool isAmplitudeLawTerm(const std::string& name) {
  for (const auto& entry : registry())
    if (entry.first == name) return entry.second()->isAmplitudeLaw();
  return false;
}

}  // namespace cvg_bench
