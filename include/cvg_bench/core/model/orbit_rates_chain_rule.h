// Orbit-element rates of any model by the chain rule (issue #26): the drift prediction comes from
// the model's own averaged equations, so a registered term contributes without anyone editing a
// drift formula. The printed (5.7)-(5.10) (test/core/model/paper_orbit_rates.h) are its known
// answer for the paper's terms.
#pragma once

#include "cvg_bench/core/model/orbit_elements.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

/// The free-oscillation model (u = 0) of a set of named values: the linear base and every
/// registered term that applies to free decay and whose parameters all appear in `values`.
ResonatorModel freeOscillationModelOf(const ParameterValues& values);

/// r', k', theta', chi' at the orbit elements e: q = slowFromOrbit(e) (5.2), q' from the model's
/// averaged equations (2.6) at time t_s (ResonatorModel::slowDerivative), r', k', theta' exactly
/// from the invariants of (5.2) along q' (chi' by central differences of orbitFromSlow), averaged
/// over 8 temporal
/// phases chi (a term that is not invariant under a common phase is averaged as (5.7)-(5.10) are).
/// Requires r^2 != k^2 and r > 0.
OrbitRates orbitRatesOfModel(const ResonatorModel& model, const ParameterValues& values,
                             const OrbitElements& e, double t_s = 0.0);

}  // namespace cvg_bench
