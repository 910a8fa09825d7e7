// AR(1) of the measurement noise along a forced sweep, from the linearized output errors of its
// points (the estimate behind the sweep's correlation-honest intervals, identification.cpp, and
// explain's sweep adequacy, diagnose/sweep_noise_model.h).
//
// A sweep's points are measured one after another, so slow disturbances (temperature, pick-off
// gain, a drifting offset) correlate the errors of neighbouring points. The equation residual of
// (3.4) at point j is e_j = -F(q_j) ~ -A_j dq_j, A_j = dF/dq (stationary_solver.h), dq_j the
// measurement error, so r_j = A_j^{-1} F(q_j) is the point's output error to first order.
// A missing effect leaves its misfit where the response is large, and a wrong model also bends
// the wings smoothly, so rho is estimated from the quiet points only (amplitude^2 <= quiet_fraction
// of the largest, in the order measured) after Legendre P_0..P_K of the drive frequency are
// removed, the pooled lag-1 correlation of the 4 components corrected for that projection
// (fitted_residual_ar1.h, bounded as there), >= 0 (slow disturbances make no negative
// correlation), capped at `ceiling`. rho = 0 (white) with fewer than min_pairs + 1 quiet points
// or below 0.05.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace cvg_bench {

struct SweepNoiseOptions {
  double quiet_fraction = 0.25;  ///< quiet point: amplitude^2 <= this x the largest, in (0, 1]
  double ceiling = 0.95;         ///< cap of rho, in (0, 1)
  int min_pairs = 8;             ///< fewer quiet pairs: white
  int degree = 3;                ///< K of the smooth part removed before the lag-1 estimate
  /// rho raised by this many standard errors sqrt((1 - rho^2) / n_quiet) before the cap, >= 0.
  /// The bounded estimate reads rho low on short sweeps; tests that whiten with it (explain) use
  /// 1 to hold their level, the intervals 0 (their coverage is measured with it).
  double upper_standard_errors = 0.0;
};

struct SweepAr1 {
  double rho = 0.0;  ///< 0: white
  bool capped = false;
  std::string description;
};

/// r: linearized output errors per point (in measurement order), amp2 = |q_j|^2, abscissa =
/// omega0_j [rad/s]; all of one size.
SweepAr1 sweepNoiseAr1(const std::vector<Eigen::Vector4d>& r, const std::vector<double>& amp2,
                       const std::vector<double>& abscissa, const SweepNoiseOptions& options = {});

}  // namespace cvg_bench
