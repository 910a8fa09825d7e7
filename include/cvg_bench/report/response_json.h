// JSON of one-mode frequency responses (docs/interfaces.md, "One-mode frequency response"): the
// identify output (also `final` of explain) and the explain output.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cvg_bench/core/single_mode/response_explain.h"

namespace cvg_bench {
namespace report {

/// {"mode": "response", "model", "method", "response", "derived_ci": {f0_hz, width_hz, Q,
///  [backbone_hz_per_amp2], [width_growth_hz_per_amp2]}, "not_determined", "interval_method",
///  "parameters" (complex gain and background), "n_points", "n_sweeps", "n_drive_levels", "jumps",
///  "rss", "sigma", "residual_lag1", "phase_conjugated", "levels", "notes"}. A quantity these data
/// cannot determine is listed in not_determined and absent from derived_ci.
nlohmann::json responseFitToJson(const ResponseFit& fit, double confidence,
                                 const std::vector<std::string>& notes);

/// {"mode": "response", "candidates": [...], "selected", "unexplained", "adequacy", "verdict",
///  "final": responseFitToJson(selected fit)}.
nlohmann::json responseExplanationToJson(const ResponseExplanation& x, double confidence,
                                         const std::vector<std::string>& notes);

}  // namespace report
}  // namespace cvg_bench
