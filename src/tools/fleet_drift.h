// The fleet table's drift columns (docs/fleet.md): for a two-mode record, the harmonics of the
// drift its model predicts over the pattern angle (core drift_measurement.h predictDriftHarmonics)
// at r = 1 record unit and k = 0, with delta-method intervals: drift_c0_deg_h, drift_4theta_deg_h,
// drift_8theta_deg_h. One-mode records (ring-down, response) get none.
#pragma once

#include <nlohmann/json.hpp>

namespace cvg_bench {
namespace tools {

void addPredictedDrift(const nlohmann::json& result, nlohmann::ordered_json& row);

}  // namespace tools
}  // namespace cvg_bench
