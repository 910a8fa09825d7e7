// The blocks of the forced-sweep regression (3.4)-(3.5): at each stationary point j,
//   y_j = rate_j (p1, -q1, p2, -q2)_j = D(q_j) z + e_j,   rate_j = detuningRate(omega, omega0_j)
// (exact first-order detuning term (omega0^2 - omega^2)/omega0, docs/paper.md item 7; the print's
// 2 lambda is its first-order part), D from ResonatorModel::regressor with the known mu.
#pragma once

#include "cvg_bench/core/estimate/free_decay_regression.h"

namespace cvg_bench {

/// Minimum number of sweep points (16 equations, section 3).
constexpr int kMinSweepPoints = 4;

/// Checks a sweep: >= kMinSweepPoints points, sizes agree, finite q, omega0 finite and > 0.
void validateSweepRecord(const SweepRecord& record);

/// Calls visit for each sweep point j (validated first). omega_rad_s > 0; mu the known control
/// nonlinearity.
void forEachForcedBlock(const ResonatorModel& model, const SweepRecord& record, double omega_rad_s,
                        double mu, const RegressionVisitor& visit);

/// forEachForcedBlock for a record that already passed validateSweepRecord (batch identification
/// streams a record twice and validates it once).
void forEachValidatedForcedBlock(const ResonatorModel& model, const SweepRecord& record,
                                 double omega_rad_s, double mu, const RegressionVisitor& visit);

}  // namespace cvg_bench
