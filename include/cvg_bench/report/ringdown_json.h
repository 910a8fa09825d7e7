// JSON of single-channel ring-downs (interfaces.md, "Single-channel ring-downs"): the identify
// output (also `final` of explain) and the explain output.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cvg_bench/core/single_mode/ringdown_causes.h"

namespace cvg_bench {
namespace report {

/// {"mode": "ringdown", "model", "method", "frequency_hz", "omega", "segment", "error_model",
///  "parameters", "derived", "derived_ci", "cramer_rao", "interval_method", "q_vs_amplitude",
///  "flags", "adequate", "notes", ...}. Infinite interval ends are written as null.
nlohmann::json ringdownFitToJson(const RingdownFit& fit, const RingdownSegment& seg,
                                 double confidence, const std::vector<std::string>& notes);

/// The explain JSON ("baseline", "steps", "selected", "unexplained", "causes", "cause",
/// "lack_of_fit", "final").
nlohmann::json ringdownExplanationToJson(const RingdownExplanation& x, double confidence,
                                         const std::vector<std::string>& notes);

}  // namespace report
}  // namespace cvg_bench
