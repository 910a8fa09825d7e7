// Noise correlated along a forced sweep, for `explain`'s adequacy test of sweeps: the AR(1) of
// estimate/uncertainty/sweep_noise_ar1.h (how and why it is estimated) as the ResidualNoiseModel
// that whitens the residual blocks. The blocks are the linearized output errors r_j = A_j^{-1}
// F(q_j) of the forced fitter's adequacyResiduals (nested_model_fitters.cpp).
#pragma once

#include <vector>

#include "cvg_bench/core/diagnose/residual_noise_model.h"
#include "cvg_bench/core/diagnose/residual_signature.h"
#include "cvg_bench/core/estimate/uncertainty/sweep_noise_ar1.h"

namespace cvg_bench {

/// The estimate as explain's tests use it: rho + 1 standard error (sweep_noise_ar1.h). On the
/// tuning seeds the plain estimate (read low on 41-81 point sweeps) called 3 of 8 clean sweeps
/// with AR(1) 0.9 along them "unexplained" (docs/explain_selection.md).
SweepNoiseOptions adequacySweepNoiseOptions();

/// AR(1) noise model of a sweep's output-error residual blocks (in measurement order).
ResidualNoiseModel noiseModelAlongSweep(
    const std::vector<BlockResidual>& blocks,
    const SweepNoiseOptions& options = adequacySweepNoiseOptions());

}  // namespace cvg_bench
