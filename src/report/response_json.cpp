// JSON of one-mode frequency responses (response_json.h).
#include "cvg_bench/report/response_json.h"

#include <algorithm>
#include <cmath>

namespace cvg_bench {
namespace report {
namespace {

nlohmann::json num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

nlohmann::json complexJson(std::complex<double> c) {
  return {{"re", num(c.real())}, {"im", num(c.imag())}};
}

}  // namespace

nlohmann::json responseFitToJson(const ResponseFit& fit, double confidence,
                                 const std::vector<std::string>& notes) {
  nlohmann::json j;
  j["mode"] = "response";
  j["model"] = fit.terms.name();
  j["method"] = "output_error";
  j["response"] = responseKindName(fit.kind);
  j["confidence"] = confidence;
  nlohmann::json dci = nlohmann::json::object();
  for (const auto& kv : fit.derived) {
    if (std::find(fit.not_determined.begin(), fit.not_determined.end(), kv.first) !=
        fit.not_determined.end())
      continue;
    dci[kv.first] = {{"value", num(kv.second.value)},
                     {"std", num(kv.second.std)},
                     {"ci_low", num(kv.second.ci_low)},
                     {"ci_high", num(kv.second.ci_high)},
                     {"dof", kv.second.dof}};
  }
  j["derived_ci"] = dci;
  j["not_determined"] = fit.not_determined;
  j["interval_method"] = fit.interval_method;
  j["parameters"] = {{"gain", complexJson(fit.params.gain)},
                     {"background", complexJson(fit.params.bg0)},
                     {"background_slope_per_hz", complexJson(fit.params.bg1)},
                     {"background_f_ref_hz", num(fit.params.f_ref_hz)}};
  j["n_points"] = fit.n_points;
  j["n_sweeps"] = fit.n_sweeps;
  j["n_drive_levels"] = fit.n_drive_levels;
  j["n_params"] = fit.n_params;
  j["jumps"] = fit.jumps;
  j["rss"] = num(fit.rss);
  j["sigma"] = num(fit.sigma);
  j["residual_lag1"] = num(fit.residual_lag1);
  j["phase_conjugated"] = fit.conjugated;
  nlohmann::json lv = nlohmann::json::array();
  for (const auto& l : fit.levels)
    lv.push_back({{"drive", num(l.drive)},
                  {"f0_hz", num(l.f0_hz)},
                  {"width_hz", num(l.width_hz)},
                  {"peak_amplitude", num(std::sqrt(l.peak_u))},
                  {"n_points", l.n_points}});
  j["levels"] = lv;
  std::vector<std::string> all = notes;
  all.insert(all.end(), fit.notes.begin(), fit.notes.end());
  j["notes"] = all;
  return j;
}

nlohmann::json responseExplanationToJson(const ResponseExplanation& x, double confidence,
                                         const std::vector<std::string>& notes) {
  nlohmann::json j;
  j["mode"] = "response";
  nlohmann::json cands = nlohmann::json::array();
  for (const auto& c : x.candidates) {
    nlohmann::json cj = {{"model", c.fit.terms.name()}, {"rss", num(c.fit.rss)},
                         {"jumps", c.fit.jumps},        {"significant", c.significant},
                         {"p_values", c.p_values},      {"effect_over_width", c.effect_over_width}};
    nlohmann::json dci = nlohmann::json::object();
    for (const auto& kv : c.fit.derived)
      dci[kv.first] = {{"value", num(kv.second.value)},
                       {"ci_low", num(kv.second.ci_low)},
                       {"ci_high", num(kv.second.ci_high)}};
    cj["derived_ci"] = dci;
    cands.push_back(cj);
  }
  j["candidates"] = cands;
  j["selected"] = x.selected;
  j["unexplained"] = x.unexplained;
  j["adequate"] = !x.unexplained;
  j["adequacy"] = {{"rss_selected", num(x.rss_selected)},
                   {"rss_free_levels", num(x.rss_free_levels)},
                   {"rss_free_level_gains", num(x.rss_free_level_gains)},
                   {"ratio", num(x.adequacy_ratio)},
                   {"threshold", num(x.adequacy_threshold)},
                   {"test", x.adequacy_test}};
  j["verdict"] = x.verdict;
  j["final"] = responseFitToJson(x.candidates.at(x.selected_index).fit, confidence, notes);
  return j;
}

}  // namespace report
}  // namespace cvg_bench
