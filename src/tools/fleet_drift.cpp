#include "fleet_drift.h"

#include <cmath>

#include "cvg_bench/core/diagnose/drift_measurement.h"
#include "cvg_bench/report/estimate_json.h"
#include "json_fields.h"

namespace cvg_bench {
namespace tools {

/// Two-mode records: the harmonics of the drift the record's model predicts over the pattern
/// angle (drift_measurement.h) at r = 1 record unit, k = 0, with intervals: c0, the 4 theta and
/// 8 theta amplitudes [deg/h]. Nothing for one-mode records (ring-down, response).
void addPredictedDrift(const nlohmann::json& result, nlohmann::ordered_json& row) {
  const std::string mode = stringField(
      (result.contains("final") && result["final"].is_object() ? result["final"] : result), "mode");
  if (mode != "free_decay" && mode != "forced") return;
  try {
    const UncertainParameters up =
        report::uncertainParameters(report::parameterFileFromJson(result, "record JSON"));
    const PredictedDriftHarmonics h = predictDriftHarmonics(up, 1.0, 0.0);
    constexpr double kDegH = 180.0 / M_PI * 3600.0;
    auto put = [&](const char* name, const ParameterEstimate& p) {
      nlohmann::ordered_json v;
      v["value"] = p.value * kDegH;
      v["std"] = p.std_error * kDegH;
      v["ci_low"] = p.ci_low * kDegH;
      v["ci_high"] = p.ci_high * kDegH;
      row[name] = v;
    };
    put("drift_c0_deg_h", h.c0);
    put("drift_4theta_deg_h", h.amp4);
    put("drift_8theta_deg_h", h.amp8);
  } catch (const std::exception&) {
    // A record whose parameters cannot be read for a prediction gets no drift columns.
  }
}

}  // namespace tools
}  // namespace cvg_bench
