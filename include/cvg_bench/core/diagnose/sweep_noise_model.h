// Noise correlated along a forced sweep, for `explain`'s adequacy test of sweeps: the AR(1) of
// estimate/sweep_noise_ar1.h (how and why it is estimated) as the ResidualNoiseModel that whitens
// the residual blocks. The blocks are the linearized output errors r_j = A_j^{-1} F(q_j) of the
// forced fitter's adequacyResiduals (nested_model_fitters.cpp).
#pragma once

#include <vector>

#include "cvg_bench/core/diagnose/residual_noise_model.h"
#include "cvg_bench/core/diagnose/residual_signature.h"
#include "cvg_bench/core/estimate/sweep_noise_ar1.h"

namespace cvg_bench {

/// AR(1) noise model of a sweep's output-error residual blocks (in measurement order).
ResidualNoiseModel noiseModelAlongSweep(const std::vector<BlockResidual>& blocks,
                                        const SweepNoiseOptions& options = {});

}  // namespace cvg_bench
