#include "cvg_bench/report/explain_json.h"

#include <cmath>

#include "cvg_bench/report/estimate_json.h"

namespace cvg_bench {
namespace report {
namespace {

/// JSON has no infinity: a hold-out ratio of a model whose prediction diverged is written as null.
nlohmann::json finiteOrNull(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nullptr;
}

nlohmann::json stepToJson(const SelectionStep& s) {
  return {{"added", s.added},
          {"model", s.model},
          {"sigma", s.sigma},
          {"sigma_ratio", finiteOrNull(s.sigma_ratio)},
          {"f_statistic", finiteOrNull(s.wald.f_statistic)},
          {"df1", s.wald.df1},
          {"df2", s.wald.df2},
          {"p_value", s.wald.p_value},
          {"threshold", s.threshold},
          {"delta_bic", finiteOrNull(s.delta_bic)},
          {"holdout_ratio", finiteOrNull(s.holdout_ratio)},
          {"delta_criterion", finiteOrNull(s.delta_criterion)},
          {"accepted", s.accepted}};
}

nlohmann::json subsetToJson(const SubsetScore& s) {
  return {{"model", s.model},
          {"terms", s.terms},
          {"criterion_ls", finiteOrNull(s.criterion_ls)},
          {"refined", s.refined},
          {"criterion", finiteOrNull(s.criterion)},
          {"sigma", s.sigma},
          {"holdout_ratio", s.holdout_ratio > 0 ? finiteOrNull(s.holdout_ratio) : nullptr}};
}

/// The selection's criterion, the chosen subset, the runner-up and the table of subsets.
nlohmann::json selectionToJson(const SelectionResult& sel) {
  nlohmann::json subsets = nlohmann::json::array();
  for (const auto& s : sel.subsets) subsets.push_back(subsetToJson(s));
  nlohmann::json runner = nullptr;
  if (!sel.runner_up.model.empty()) {
    runner = subsetToJson(sel.runner_up);
    runner["delta_criterion"] = finiteOrNull(sel.runner_up_delta);
  }
  return {{"criterion", sel.criterion_description},
          {"correlation_factor_ls", sel.correlation_factor_ls},
          {"correlation_factor", sel.correlation_factor},
          {"chosen", subsetToJson(sel.chosen)},
          {"runner_up", runner},
          {"subsets", subsets}};
}

nlohmann::json signatureToJson(const ResidualSignature& sig) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& e : sig.entries)
    a.push_back({{"variable", e.variable},
                 {"component", e.component},
                 {"correlation", e.correlation},
                 {"p_value", e.p_value},
                 {"n_used", e.n_used}});
  return a;
}

}  // namespace

namespace {

nlohmann::json estimateWithCi(const ParameterEstimate& p, double scale = 1.0) {
  return {{"value", p.value * scale},
          {"std", p.std_error * scale},
          {"ci_low", p.ci_low * scale},
          {"ci_high", p.ci_high * scale}};
}

}  // namespace

nlohmann::json quadratureGrowthToJson(const QuadratureGrowth& g) {
  if (!g.valid) return {{"valid", false}, {"why_not", g.why_not}};
  nlohmann::json shares = nlohmann::json::array();
  for (const QuadratureShare& s : g.shares)
    shares.push_back({{"parameters", s.parameters},
                      {"meaning", s.meaning},
                      {"widening_per_s", estimateWithCi(s.widening)},
                      {"determined", s.determined}});
  return {{"valid", true},
          {"what",
           "d|k|/dt of the selected model at the record's median state, split into the shares of "
           "its parameter groups (what the rate loses when the group is set to 0); groups the "
           "covariance cannot tell apart are one share; measured = the record's k' with k's sign"},
          {"r", g.r},
          {"k", g.k},
          {"theta_rad", g.theta_rad},
          {"measured_widening_per_s", estimateWithCi(g.measured_widening)},
          {"predicted_widening_per_s", estimateWithCi(g.predicted_widening)},
          {"shares", shares},
          {"named", g.named},
          {"summary", g.summary}};
}

nlohmann::json orbitReadingToJson(const OrbitReading& m) {
  constexpr double kDegH = 180.0 / M_PI * 3600.0;
  nlohmann::json j;
  j["what"] =
      "model-free reading: orbit elements (5.2) of the slow samples in equal windows of time; "
      "rates are least-squares slopes with HAC standard errors, the record's rate the mean of the "
      "windows' with a Student-t interval from their scatter";
  j["period_s"] = m.period_s;
  j["n_samples"] = m.n_samples;
  j["theta_rate_rad_s"] = estimateWithCi(m.theta_rate);
  j["theta_rate_deg_h"] = estimateWithCi(m.theta_rate, kDegH);
  // The angle of the (f, g) ellipse's major axis (a pendulum's swing plane) is 2 theta (5.2).
  j["oscillation_plane_rate_deg_h"] = estimateWithCi(m.theta_rate, 2.0 * kDegH);
  j["k_rate_per_s"] = estimateWithCi(m.k_rate);
  j["model"] = m.model;
  nlohmann::json w = nlohmann::json::array();
  for (const auto& x : m.windows) {
    nlohmann::json o = {{"t_start_s", x.t_start_s},
                        {"t_end_s", x.t_end_s},
                        {"n", x.n},
                        {"r", x.r},
                        {"k", x.k},
                        {"theta_rad", x.theta_rad},
                        {"theta_rate_deg_h", estimateWithCi(x.theta_rate, kDegH)},
                        {"k_rate_per_s", estimateWithCi(x.k_rate)}};
    o["Q"] = x.q.value > 0.0 ? estimateWithCi(x.q) : nlohmann::json(nullptr);
    o["predicted_theta_rate_deg_h"] =
        x.has_prediction ? estimateWithCi(x.predicted_theta_rate, kDegH) : nlohmann::json(nullptr);
    o["predicted_k_rate_per_s"] =
        x.has_prediction ? estimateWithCi(x.predicted_k_rate) : nlohmann::json(nullptr);
    w.push_back(o);
  }
  j["windows"] = w;
  j["quadrature_growth"] = quadratureGrowthToJson(m.quadrature_growth);
  auto slope = [](const ParameterEstimate& e) {
    return e.std_error > 0.0 ? estimateWithCi(e) : nlohmann::json(nullptr);
  };
  j["rk_slope"] = {
      {"what",
       "windows' theta' [rad/s] against r k / 8 (least squares, error from the windows' "
       "scatter, Student-t): the "
       "coupling the record shows, and the same slope of the model's predictions"},
      {"measured_per_s_amp2", slope(m.rk_slope_measured)},
      {"model_per_s_amp2", slope(m.rk_slope_model)}};
  j["summary"] = m.summary;
  return j;
}

nlohmann::json explanationToJson(const Explanation& x) {
  nlohmann::json j;
  j["mode"] = experimentModeName(x.mode);
  j["baseline"] = {{"model", x.selection.baseline.model}, {"sigma", x.selection.baseline.sigma}};
  nlohmann::json steps = nlohmann::json::array();
  for (const auto& s : x.selection.steps) steps.push_back(stepToJson(s));
  j["steps"] = steps;
  j["selected"] = x.selection.selected;
  j["dropped"] = x.selection.dropped;
  j["selection"] = selectionToJson(x.selection);
  j["runner_up"] =
      x.selection.runner_up.model.empty()
          ? nlohmann::json(nullptr)
          : nlohmann::json({{"model", x.selection.runner_up.model},
                            {"terms", x.selection.runner_up.terms},
                            {"delta_criterion", finiteOrNull(x.selection.runner_up_delta)}});
  j["unexplained"] = x.unexplained;
  j["determined"] = x.determined;
  j["lack_of_fit"] = {{"test", x.lack_of_fit.test},
                      {"p_value", x.lack_of_fit.p_value},
                      {"worst", x.lack_of_fit.worst},
                      {"noise_model", x.lack_of_fit.noise_model},
                      {"p_value_unwhitened", x.lack_of_fit.p_value_unwhitened},
                      {"runs_p_value", x.lack_of_fit.runs_p_value},
                      {"low_frequency_p_value", x.lack_of_fit.low_frequency_p_value},
                      {"low_frequency", x.lack_of_fit.low_frequency},
                      {"signature_p_value", x.lack_of_fit.signature_p_value}};
  j["cause"] = x.cause;
  nlohmann::json rejected = nlohmann::json::array();
  for (const auto& s : x.selection.last_round) rejected.push_back(stepToJson(s));
  j["rejected"] = rejected;
  j["signature"] = signatureToJson(x.baseline_signature);
  j["signature_summary"] = x.baseline_signature.describe(0.01);
  j["final_signature"] = signatureToJson(x.final_signature);
  j["holdout"] = x.selection.holdout_description;
  j["notes"] = x.notes;
  j["final"] = estimateToJson(x.finalEstimate());
  if (x.measured.valid) j["measured"] = orbitReadingToJson(x.measured);
  return j;
}

}  // namespace report
}  // namespace cvg_bench
