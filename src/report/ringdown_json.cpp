#include "cvg_bench/report/ringdown_json.h"

#include <cmath>

#include "cvg_bench/core/single_mode/ringdown_envelope.h"

namespace cvg_bench {
namespace report {
namespace {

nlohmann::json num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

nlohmann::json valueJson(const RingdownValue& v) {
  nlohmann::json j = {{"value", num(v.value)},
                      {"std", num(v.std)},
                      {"ci_low", num(v.ci_low)},
                      {"ci_high", num(v.ci_high)}};
  if (v.crb_std > 0.0) j["crb_std"] = num(v.crb_std);
  if (std::isfinite(v.std_span)) {
    // The within-record interval above; the span choice's part and the total beside it.
    j["std_within"] = num(v.std);
    j["std_span"] = num(v.std_span);
    j["std_total"] = num(v.std_total);
    j["ci_total_low"] = num(v.ci_total_low);
    j["ci_total_high"] = num(v.ci_total_high);  // null: open above
  }
  return j;
}

}  // namespace

nlohmann::json ringdownFitToJson(const RingdownFit& fit, const RingdownSegment& seg,
                                 double confidence, const std::vector<std::string>& notes) {
  nlohmann::json j;
  j["mode"] = "ringdown";
  j["model"] = fit.model;
  j["method"] = "wls_log";
  j["frequency_hz"] = num(fit.frequency_hz);
  j["omega"] = num(2.0 * M_PI * fit.frequency_hz);
  j["q_convention"] = "Q = omega tau / 2 = pi f tau, tau the amplitude (not energy) time constant";
  j["n_equations"] = fit.n;
  j["n_params"] = fit.n_params;
  j["rank"] = fit.rank;
  j["unidentifiable"] = nlohmann::json::array();
  j["sigma"] = num(fit.sigma);
  j["rms_residual_db"] = num(fit.rms_log * kDbPerNeper);
  j["residual_lag1_correlation"] = num(fit.rho1);
  j["confidence"] = confidence;
  j["segment"] = {
      {"t_start", seg.t_start_s},
      {"t_end", seg.t_end_s},
      {"why", seg.why},
      {"has_plateau", seg.has_plateau},
      {"drive_off_s", seg.drive_off_s},
      {"has_floor", seg.has_floor},
      {"floor_db", seg.has_floor ? num(seg.floor_log_amplitude * kDbPerNeper) : nlohmann::json()},
      {"n_used", seg.n_used},
      {"n_dropouts", seg.n_dropouts_in_span},
      {"decay_db", num(seg.decay_db)}};
  j["error_model"] = {{"name", fit.error_model}, {"why", fit.error_model_why}};
  nlohmann::json params = nlohmann::json::object(), derived = nlohmann::json::object(),
                 dci = nlohmann::json::object(), crb = nlohmann::json::object();
  for (const auto& kv : fit.parameters) params[kv.first] = valueJson(kv.second);
  for (const auto& kv : fit.derived) {
    derived[kv.first] = num(kv.second.value);
    dci[kv.first] = valueJson(kv.second);
    if (kv.second.crb_std > 0.0)
      crb[kv.first] = {{"crb_std", num(kv.second.crb_std)},
                       {"interval_std_over_crb", num(kv.second.std / kv.second.crb_std)}};
  }
  j["parameters"] = params;
  j["derived"] = derived;
  j["derived_ci"] = dci;
  j["cramer_rao"] = crb;
  j["interval_method"] = fit.interval_method;
  j["residual_noise_model"] = {{"ar_order", fit.noise_ar_order},
                               {"long_run_variance_factor", num(fit.long_run_factor)},
                               {"effective_n", num(fit.effective_n)}};
  nlohmann::json qa = nlohmann::json::array();
  for (const auto& b : fit.q_vs_amplitude)
    qa.push_back({{"amplitude", num(b.amplitude)},
                  {"level_db", num(b.level_db)},
                  {"t_start", b.t_start_s},
                  {"t_end", b.t_end_s},
                  {"n", b.n},
                  {"decay_rate_1_s", num(b.decay_rate_1_s)},
                  {"Q", valueJson(b.Q)}});
  j["q_vs_amplitude"] = qa;
  j["flags"] = fit.flags;
  j["adequate"] = fit.flags.empty();
  j["notes"] = notes;
  return j;
}

nlohmann::json ringdownExplanationToJson(const RingdownExplanation& x, double confidence,
                                         const std::vector<std::string>& notes) {
  nlohmann::json j;
  j["mode"] = "ringdown";
  j["baseline"] = {{"model", "linear"}, {"sigma", num(x.baseline.sigma)}};
  nlohmann::json steps = nlohmann::json::array();
  for (const auto& s : x.steps)
    steps.push_back({{"added", s.added},
                     {"model", "linear+" + s.added},
                     {"sigma", num(s.sigma)},
                     {"sigma_ratio", num(s.sigma_ratio)},
                     {"lr_statistic", num(s.lr_statistic)},
                     {"threshold", num(s.threshold)},
                     {"n_eff", num(s.n_eff)},
                     {"p_value", num(s.p_value)},
                     {"significant", s.significant},
                     {"sign_check_passed", s.physical},
                     {"accepted", s.accepted},
                     {"information_criterion", num(s.information_criterion)},
                     {"hold_out_error", num(s.hold_out_error)},
                     {"hold_out_reference", num(s.hold_out_reference)},
                     {"effect_db", num(s.effect_db)},
                     {"effect_over_rms", num(s.effect_over_rms)},
                     {"note", s.note}});
  j["steps"] = steps;
  j["selection"] = {{"criterion",
                     "BIC on the effective sample size; beat and two_stage must also "
                     "beat the physical amplitude laws; pick confirmed on hold-out"},
                    {"information_criterion", x.information_criterion}};
  const RingdownDetectorFilter& df = x.detector_filter;
  j["detector_filter"] = {
      {"found", df.found},
      {"source", df.source},
      {"order", df.order},
      {"time_constant_s", df.found ? num(df.time_constant_s) : nlohmann::json()},
      {"why", df.why}};
  j["law_choice"] = {{"why", x.law_choice}, {"sse_whitened", x.law_choice_sse}};
  j["selected"] = x.selected;
  j["unexplained"] = x.unexplained;
  j["adequate"] = x.adequate;
  j["causes"] = x.causes;
  j["lack_of_fit"] = {{"test", x.lack_of_fit_test},
                      {"p_value", num(x.lack_of_fit_p)},
                      {"rate_variation", num(x.lack_of_fit_rate_variation)},
                      {"negative_law_rate_variation", num(x.negative_law_rate_variation)}};
  j["cause"] = x.cause;
  j["final"] = ringdownFitToJson(x.final_fit, x.segment, confidence, notes);
  j["final"]["model"] = x.selected.empty() ? "linear" : "linear+" + x.selected.front();
  j["final"]["adequate"] = x.adequate;
  return j;
}

}  // namespace report
}  // namespace cvg_bench
