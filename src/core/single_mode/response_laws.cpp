// The one-mode response terms (response_laws.h).
#include "cvg_bench/core/single_mode/response_laws.h"

#include "cvg_bench/core/model/gamma_nl_conventions.h"

namespace cvg_bench {
namespace {

const char* backboneWords(double v) {
  return v < 0 ? "softening backbone" : "hardening backbone";
}

const char* widthGrowthWords(double v) {
  return v > 0 ? "width grows with amplitude" : "width falls with amplitude";
}

ResponseLaw backboneLaw() {
  ResponseLaw law;
  law.name = "xi";
  law.flag = &ResponseTerms::backbone;
  law.coefficient = &ResponseParams::backbone_hz_per_amp2;
  law.derived_key = "backbone_hz_per_amp2";
  law.unit = "Hz/amp^2";
  law.description =
      "backbone: the resonance frequency's shift per amplitude^2 (Duffing, cubic stiffness)";
  law.verdict_words = backboneWords;
  return law;
}

ResponseLaw widthGrowthLaw() {
  ResponseLaw law;
  law.name = "gamma_nl";
  law.flag = &ResponseTerms::width_growth;
  law.coefficient = &ResponseParams::width_growth_hz_per_amp2;
  law.derived_key = "width_growth_hz_per_amp2";
  law.unit = "Hz/amp^2";
  law.description =
      "amplitude-dependent damping: the half-power width's growth per amplitude^2, either sign";
  law.verdict_words = widthGrowthWords;
  law.model_term_key = "gamma_nl_term";
  law.model_term_per_unit = kGammaNlTermPerWidthGrowthHz;
  return law;
}

}  // namespace

const std::vector<ResponseLaw>& responseLaws() {
  static const std::vector<ResponseLaw> laws = {backboneLaw(), widthGrowthLaw()};
  return laws;
}

const ResponseLaw* findResponseLaw(const std::string& name) {
  for (const ResponseLaw& law : responseLaws())
    if (name == law.name) return &law;
  return nullptr;
}

std::vector<ResponseTerms> responseTermCombinations() {
  const std::vector<ResponseLaw>& laws = responseLaws();
  std::vector<ResponseTerms> all;
  for (size_t mask = 0; mask < (size_t{1} << laws.size()); ++mask) {
    ResponseTerms t;
    for (size_t i = 0; i < laws.size(); ++i) t.*laws[i].flag = (mask >> i) & 1u;
    all.push_back(t);
  }
  return all;
}

int responseTermCount(const ResponseTerms& t) {
  int n = 0;
  for (const ResponseLaw& law : responseLaws()) n += t.*law.flag ? 1 : 0;
  return n;
}

}  // namespace cvg_bench
