// Registry of the one-mode response terms (response_model.h): the amplitude laws a driven mode's
// stationary response may have besides the linear Lorentzian, one record per term holding what
// the parser, the fit, the selection and the command line need to know of it by name. A model is
// `linear` or its terms' names joined by '+' in table order (ResponseTerms::name).
//
// How to add a term: give it a flag in ResponseTerms and a coefficient in ResponseParams, put it in
// the model's equation (response_model.cpp: cubicAt, stationaryResponse) and the generator
// (core/simulate/response_simulator.*), give it a start in the fit (response_fit.cpp, startsOf:
// the per-level trend it follows), and add its record to the table in responseLaws() (order: the
// parameter order of the fit, the print order, the verdict's order). The parser, the names, the
// explain candidates (every combination), the p values, the derived keys, the printout and
// --effect then follow the table. State it in docs/response.md and docs/interfaces.md.
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/single_mode/response_model.h"

namespace cvg_bench {

/// One term of the one-mode response model.
struct ResponseLaw {
  /// Name in --model, --effect and explain's per-term maps (p_values, effect_over_width).
  const char* name = nullptr;
  /// The ResponseTerms flag it sets.
  bool ResponseTerms::*flag = nullptr;
  /// Its coefficient in ResponseParams (per amplitude^2 of the input's unit).
  double ResponseParams::*coefficient = nullptr;
  /// Its key in ResponseFit::derived, not_determined and the JSON.
  const char* derived_key = nullptr;
  /// Unit of the derived value as the verdict prints it.
  const char* unit = nullptr;
  /// What it is, in a line.
  const char* description = nullptr;
  /// The verdict's words for a fitted value (before the number), e.g. "softening backbone".
  const char* (*verdict_words)(double value) = nullptr;
  /// Key of the model term's coefficient it converts to (gamma_nl_conventions.h), nullptr if none.
  const char* model_term_key = nullptr;
  /// The model term's coefficient per unit of the derived value (with model_term_key).
  double model_term_per_unit = 0.0;
};

/// Name of the model without terms.
inline constexpr const char* kLinearResponseModel = "linear";

/// The terms, in the fit's parameter order.
const std::vector<ResponseLaw>& responseLaws();

/// The term of that name; nullptr for an unknown name.
const ResponseLaw* findResponseLaw(const std::string& name);

/// Every model of the terms (background slope off), explain's candidates: bit i of the index is
/// term i of the table, so linear first and all terms together last (two terms: linear, xi,
/// gamma_nl, xi+gamma_nl).
std::vector<ResponseTerms> responseTermCombinations();

/// How many terms `t` has (the background slope is not a term).
int responseTermCount(const ResponseTerms& t);

}  // namespace cvg_bench
