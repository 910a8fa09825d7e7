// A whole-angle run (issue #26): amplitude and quadrature control loops hold r and k, the pattern
// angle theta is free and is walked over more than a full period (pi/2) by a base rotation, so the
// drift theta'(theta) can be measured and set against the identified model's prediction.
//
// The averaged model is integrated in orbit elements: r' = k' = 0 (ideal loops; with a finite gain
// g, r' = r'_model + g (r0 - r), k' = k'_model + g (k0 - k): a split then leaves k off k0 and the
// pattern may lock), theta' = theta'_model + walk, chi' = chi'_model, the model's rates by
// the chain rule over its averaged equations (orbit_rates_chain_rule.h). Ideal loops act on r and k
// only (they add nothing to theta'); the walk is the pattern's response to the base rotation
// (-K Omega for angular gain K), a known rate the measurement subtracts. q = (5.2) of the elements
// plus the preset's white noise on q.
#pragma once

#include <cstdint>

#include "cvg_bench/core/io/records.h"
#include "cvg_bench/core/model/resonator_preset.h"

namespace cvg_bench {

struct WholeAngleOptions {
  double r0 = 0.5;              ///< amplitude held [record units], > 0
  double k0 = 0.0;              ///< quadrature held, |k0| < r0
  double loop_rate_1_s = 0.0;   ///< loop gain g [1/s]; 0 = ideal loops (r and k held exactly)
  double walk_rad_s = 0.0;      ///< base-rotation walk of theta [rad/s]; 0 = 1.5 x (pi/2) over the
                                ///< run and at least 4x the resonator's largest drift (no lock)
  double duration_s = 0.0;      ///< 0 = the preset's free-decay duration x 20
  double sample_rate_hz = 0.0;  ///< 0 = the preset's free-decay rate
  double noise_std = -1.0;      ///< on q; < 0 = the preset's
  std::uint64_t seed = 1;
};

/// The run as a slow record t,q1,p1,q2,p2 with `# whole_angle_*` lines (r0, k0, loop rate, walk)
/// and the preset's truth. InputError for bad options.
SlowRecord simulateWholeAngle(const ResonatorPreset& preset, const WholeAngleOptions& options);

}  // namespace cvg_bench
