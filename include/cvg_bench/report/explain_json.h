// JSON form of an Explanation (interfaces.md "explain"), plus fields beyond the contract:
// steps[].accepted/df1/df2/threshold, rejected (candidates of the round that stopped the
// selection), dropped (backward check), signature / final_signature (residual structure),
// holdout (how the hold-out is made), notes, measured (free decay: the orbit before any model).
#pragma once

#include <nlohmann/json.hpp>

#include "cvg_bench/core/diagnose/explanation.h"

namespace cvg_bench {
namespace report {

nlohmann::json explanationToJson(const Explanation& x);
/// "measured" of explain's JSON (free decay): the model-free orbit reading (orbit_reading.h).
/// quadrature_growth.h as JSON (orbitReadingToJson's "quadrature_growth").
nlohmann::json quadratureGrowthToJson(const QuadratureGrowth& g);
nlohmann::json orbitReadingToJson(const OrbitReading& m);

}  // namespace report
}  // namespace cvg_bench
