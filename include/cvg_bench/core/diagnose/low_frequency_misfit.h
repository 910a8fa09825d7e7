// The structured adequacy test of `explain` in free decay: is there a slowly varying component in
// the trajectory residuals that the noise cannot make?
//
// A missing effect leaves a residual that varies smoothly along the record (it follows the
// amplitude, which decays monotonically, or time); coloured measurement noise spreads its power
// over all frequencies. Per residual sequence x_t (radial, tangential and the 4 components of
// q_measured - q_model at times t):
//   1. the known noise correlation (a demodulated record's noise_correlation) is removed first by
//      its AR(p) filter (residual_noise_model.h), applied to x and to the basis below;
//   2. B = Legendre polynomials P_0..P_K of the scaled time s = 2 (t - t_0) / T - 1;
//   3. the remaining noise is AR(1) with rho estimated from u = x - B b_OLS, i.e. AFTER the smooth
//      part is removed: a misfit cannot pass itself off as correlated noise (the lag-1 correlation
//      of a smooth misfit is ~1 and would otherwise drive rho to 1 and whiten the misfit away);
//      rho is capped at rho_ceiling: a correlation time beyond ~20 samples cannot be told from a
//      misfit on one record, and is treated as one;
//   4. GLS F-test that all K + 1 coefficients are zero, on the Prais-Winsten-whitened x and B:
//        F = ((|w|^2 - RSS_1) / (K + 1)) / (RSS_1 / (n - K - 1)),  F(K + 1, n - K - 1).
// The p-values of the 6 sequences are Bonferroni-combined.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "cvg_bench/core/diagnose/residual_noise_model.h"
#include "cvg_bench/core/diagnose/residual_signature.h"

namespace cvg_bench {

struct LowFrequencyMisfitTest {
  double p_value = 1.0;     ///< Bonferroni-combined over the sequences
  std::string worst;        ///< the sequence with the smallest p-value, in words
  double rho_max = 0.0;     ///< largest fitted AR(1) coefficient (after the cap)
  bool rho_capped = false;  ///< some sequence's fitted rho exceeded the ceiling
  std::string description;  ///< the test in words
};

struct LowFrequencyOptions {
  int degree = 5;             ///< K: Legendre degree of the smooth basis, 1..12
  double rho_ceiling = 0.95;  ///< cap of the fitted AR(1) coefficient, in (0, 1)
  int threads = 1;            ///< the 6 sequences tested this many at a time (0 = all cores)
};

/// The test of one sequence; p-value in [0, 1] (1 when too short: n < 4 (K + 1)).
double lowFrequencyPValue(const std::vector<double>& x, const std::vector<double>& t,
                          const ResidualNoiseModel& known, const LowFrequencyOptions& options,
                          double* rho_used = nullptr, bool* capped = nullptr);

/// The test of the adequacy residual blocks (radial, tangential, 4 components; abscissa = time).
LowFrequencyMisfitTest lowFrequencyMisfit(const std::vector<BlockResidual>& blocks,
                                          const ResidualNoiseModel& known,
                                          const LowFrequencyOptions& options = {});

}  // namespace cvg_bench
