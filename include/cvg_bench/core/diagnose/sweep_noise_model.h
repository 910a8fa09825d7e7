// Noise correlated along a forced sweep, for `explain`'s adequacy test of sweeps.
//
// A sweep's points are measured one after another, so slow disturbances (temperature, pick-off
// gain, a drifting offset) make the measurement errors of neighbouring points correlated. The
// equation residuals (3.4) of an adequate model are e_j = -F(q_j) ~ -A_j dq_j with A_j = dF/dq of
// the stationary equations (stationary_solver.h) and dq_j the measurement error, so
//   r_j = A_j^{-1} F(q_j)
// is the point's displacement from the model's stationary point to first order: the output error
// without solving for the stationary point (forcedOutputErrorResiduals, nested_model_fitters.cpp).
// Its correlation along the sweep is the noise's own.
//
// A missing effect leaves its misfit where the response is large (every nonlinear term grows
// with the amplitude squared or faster, and an error of the linear terms matters most at
// resonance), so the AR(1) coefficient is estimated from the quiet points only (amplitude^2 at
// most `quiet_fraction` of the largest, in the order measured). A misfit of the wrong model also
// bends the wings smoothly (the linear model fitted to a cubic resonance: lag-1 correlation ~1,
// whitening it away), so, as in free decay (low_frequency_misfit.h), Legendre polynomials
// P_0..P_K of the drive frequency are removed first, the lag-1 correlation of what remains
// (4 components pooled) is corrected for that projection (fitted_residual_ar1.h) and capped at
// `ceiling`. White when there are fewer than `min_pairs` + 1 quiet points or |rho| < 0.05.
#pragma once

#include <vector>

#include "cvg_bench/core/diagnose/residual_noise_model.h"
#include "cvg_bench/core/diagnose/residual_signature.h"

namespace cvg_bench {

struct SweepNoiseOptions {
  double quiet_fraction = 0.25;  ///< quiet point: amplitude^2 <= this x the largest, in (0, 1]
  double ceiling = 0.95;         ///< cap of rho, in (0, 1)
  int min_pairs = 8;             ///< fewer quiet pairs: white
  int degree = 3;                ///< K of the smooth part removed before the lag-1 estimate
};

/// AR(1) noise model of a sweep's output-error residual blocks (in measurement order).
ResidualNoiseModel noiseModelAlongSweep(const std::vector<BlockResidual>& blocks,
                                        const SweepNoiseOptions& options = {});

}  // namespace cvg_bench
