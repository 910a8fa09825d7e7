// Term selection and adequacy for one mode's response (response_explain.h).
#include "cvg_bench/core/single_mode/response_explain.h"

#include <algorithm>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <cstdio>

namespace cvg_bench {
namespace {

const char* const kTermKey[] = {"backbone_hz_per_amp2", "width_growth_hz_per_amp2"};
const char* const kTermName[] = {"xi", "gamma_nl"};

/// Two-sided p of a term from its interval's t (value / std, the fit's dof); 1 when the data
/// cannot determine it.
double termP(const ResponseFit& f, int term) {
  const std::string key = kTermKey[term];
  if (std::find(f.not_determined.begin(), f.not_determined.end(), key) != f.not_determined.end())
    return 1.0;
  const auto it = f.derived.find(key);
  if (it == f.derived.end() || !(it->second.std > 0)) return 1.0;
  const double t = std::abs(it->second.value / it->second.std);
  if (!std::isfinite(t)) return 1.0;
  boost::math::students_t dist(std::max(1, it->second.dof > 0 ? it->second.dof : f.interval_dof));
  return 2.0 * boost::math::cdf(boost::math::complement(dist, t));
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), f, v);
  return buf;
}

}  // namespace

ResponseExplanation explainResponse(const ResponseData& data, const ResponseExplainOptions& o) {
  ResponseExplanation x;
  const ResponseTerms kinds[4] = {
      {false, false, false}, {true, false, false}, {false, true, false}, {true, true, false}};
  for (const ResponseTerms& t : kinds) {
    ResponseCandidate c;
    ResponseFitOptions fo = o.fit;
    fo.level_gain_check = true;
    fo.require_resonance = false;  // the selected fit only, below
    c.fit = fitResponse(data, t, fo);
    bool all = true;
    const double u_max = c.fit.u.empty() ? 0.0 : *std::max_element(c.fit.u.begin(), c.fit.u.end());
    const double w = c.fit.derived.at("width_hz").value;
    for (int term = 0; term < 2; ++term) {
      if (!(term == 0 ? t.backbone : t.width_growth)) continue;
      const double p = termP(c.fit, term);
      const double effect = std::abs(c.fit.derived.at(kTermKey[term]).value) * u_max / w;
      c.p_values[kTermName[term]] = p;
      c.effect_over_width[kTermName[term]] = effect;
      all = all && p < o.alpha && effect >= o.min_effect_over_width;
    }
    c.significant = all && (t.backbone || t.width_growth);
    x.candidates.push_back(c);
  }
  // Joint model when both terms pass there; else the passing single term with the smaller p.
  size_t pick = 0;
  if (x.candidates[3].significant) {
    pick = 3;
  } else {
    const bool s1 = x.candidates[1].significant, s2 = x.candidates[2].significant;
    if (s1 && s2)
      pick = x.candidates[1].p_values["xi"] <= x.candidates[2].p_values["gamma_nl"] ? 1 : 2;
    else if (s1)
      pick = 1;
    else if (s2)
      pick = 2;
  }
  x.selected_index = pick;
  const ResponseFit& sel = x.candidates[pick].fit;
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
                            fmt("%.3g", x.adequacy_ratio) +
                            "x that with a free drive factor per level); best model " + x.selected
                  : x.selected == "linear" ? "linear"
                                           : x.selected;
  auto d = [&](const char* k) { return sel.derived.at(k).value; };
  v += "; f0 " + fmt("%.8g", d("f0_hz")) + " Hz, width " + fmt("%.4g", d("width_hz")) + " Hz, Q " +
       fmt("%.4g", d("Q"));
  if (sel.terms.backbone)
    v += std::string("; ") + (d("backbone_hz_per_amp2") < 0 ? "softening" : "hardening") +
         " backbone " + fmt("%.4g", d("backbone_hz_per_amp2")) + " Hz/amp^2";
  if (sel.terms.width_growth)
    v += std::string("; width ") + (d("width_growth_hz_per_amp2") > 0 ? "grows" : "falls") +
         " with amplitude " + fmt("%.4g", d("width_growth_hz_per_amp2")) + " Hz/amp^2";
  if (sel.jumps > 0) v += "; " + std::to_string(sel.jumps) + " jumps reproduced by the branch";
  x.verdict = v;
  return x;
}

}  // namespace cvg_bench
