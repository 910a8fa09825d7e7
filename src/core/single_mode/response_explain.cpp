// Term selection and adequacy for one mode's response (response_explain.h).
#include "cvg_bench/core/single_mode/response_explain.h"

#include <algorithm>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>

#include "cvg_bench/core/common/number_text.h"
#include "cvg_bench/core/single_mode/response_laws.h"

namespace cvg_bench {
namespace {

/// Two-sided p of a term from its interval's t (value / std, the fit's dof); 1 when the data
/// cannot determine it.
double termP(const ResponseFit& f, const ResponseLaw& law) {
  const std::string key = law.derived_key;
  if (std::find(f.not_determined.begin(), f.not_determined.end(), key) != f.not_determined.end())
    return 1.0;
  const auto it = f.derived.find(key);
  if (it == f.derived.end() || !(it->second.std > 0)) return 1.0;
  const double t = std::abs(it->second.value / it->second.std);
  if (!std::isfinite(t)) return 1.0;
  boost::math::students_t dist(std::max(1, it->second.dof > 0 ? it->second.dof : f.interval_dof));
  return 2.0 * boost::math::cdf(boost::math::complement(dist, t));
}

/// The model with the most terms of those whose every term passes; among as many terms, the one
/// whose largest p is smallest (the earlier on a tie); linear (0) when none passes. With two terms:
/// the joint model when both pass there, else the passing single term with the smaller p.
size_t selectCandidate(const std::vector<ResponseCandidate>& candidates) {
  size_t pick = 0;
  int pick_terms = 0;
  double pick_p = 0.0;
  for (size_t i = 0; i < candidates.size(); ++i) {
    const ResponseCandidate& c = candidates[i];
    if (!c.significant) continue;
    const int terms = responseTermCount(c.fit.terms);
    double p = 0.0;
    for (const auto& kv : c.p_values) p = std::max(p, kv.second);
    if (terms > pick_terms || (terms == pick_terms && p < pick_p)) {
      pick = i;
      pick_terms = terms;
      pick_p = p;
    }
  }
  return pick;
}

}  // namespace

ResponseExplanation explainResponse(const ResponseData& data, const ResponseExplainOptions& o) {
  ResponseExplanation x;
  for (const ResponseTerms& t : responseTermCombinations()) {
    ResponseCandidate c;
    ResponseFitOptions fo = o.fit;
    fo.level_gain_check = true;
    fo.require_resonance = false;  // the selected fit only, below
    c.fit = fitResponse(data, t, fo);
    bool all = true;
    const double u_max = c.fit.u.empty() ? 0.0 : *std::max_element(c.fit.u.begin(), c.fit.u.end());
    const double w = c.fit.derived.at("width_hz").value;
    for (const ResponseLaw& law : responseLaws()) {
      if (!(t.*law.flag)) continue;
      const double p = termP(c.fit, law);
      const double effect = std::abs(c.fit.derived.at(law.derived_key).value) * u_max / w;
      c.p_values[law.name] = p;
      c.effect_over_width[law.name] = effect;
      all = all && p < o.alpha && effect >= o.min_effect_over_width;
    }
    c.significant = all && responseTermCount(t) > 0;
    x.candidates.push_back(c);
  }
  x.selected_index = selectCandidate(x.candidates);
  const ResponseFit& sel = x.candidates[x.selected_index].fit;
  if (o.fit.require_resonance && o.fit.intervals) requireResponseResonance(sel);
  x.selected = sel.terms.name();
  // Adequacy against free Lorentzians per drive level.
  x.adequacy_threshold = o.adequacy_threshold;
  x.rss_selected = sel.rss;
  for (const auto& l : sel.levels) x.rss_free_levels += l.rss;
  x.rss_free_level_gains = sel.rss_free_level_gains;
  if (sel.levels.size() >= 2 && x.rss_free_level_gains > 0) {
    x.adequacy_ratio = x.rss_selected / x.rss_free_level_gains;
    x.unexplained = x.adequacy_ratio > o.adequacy_threshold;
    x.adequacy_test =
        "RSS of the selected model over its RSS with a free drive factor per level (" +
        std::to_string(sel.levels.size()) + " levels)";
  } else {
    x.adequacy_test = "one drive level: no check of the amplitude law against free per-level fits";
  }
  // The verdict in words.
  std::string v = x.unexplained
                      ? "unexplained: the drive levels differ in a way no amplitude law "
                        "of the model follows (RSS " +
                            printfGText(x.adequacy_ratio, 3) +
                            "x that with a free drive factor per level); best model " + x.selected
                      : x.selected;
  auto d = [&](const char* k) { return sel.derived.at(k).value; };
  v += "; f0 " + printfGText(d("f0_hz"), 8) + " Hz, width " + printfGText(d("width_hz"), 4) +
       " Hz, Q " + printfGText(d("Q"), 4);
  for (const ResponseLaw& law : responseLaws())
    if (sel.terms.*law.flag)
      v += std::string("; ") + law.verdict_words(d(law.derived_key)) + " " +
           printfGText(d(law.derived_key), 4) + " " + law.unit;
  if (sel.jumps > 0) v += "; " + std::to_string(sel.jumps) + " jumps reproduced by the branch";
  x.verdict = v;
  return x;
}

}  // namespace cvg_bench
