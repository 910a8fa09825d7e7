// One amplitude-dependent damping, three outputs that name it gamma_nl (docs/interfaces.md,
// "gamma_nl in three conventions"). The model term (nonlinear_damping_term.cpp) is the reference:
//   -gamma_nl (f^2 + g^2) f' in the f equation [1/(s amp^2)]; for one mode its first harmonic is
//   an effective damping gamma + gamma_nl A^2 / 4 (A the displacement amplitude).
// A ring-down fits the amplitude decay rate g0 + gamma_nl_rd A^2 = (gamma + gamma_nl A^2 / 4) / 2,
// so gamma_nl = 8 gamma_nl_rd. A one-mode response fits the half-power width [Hz]
// w0 + g A^2 = (gamma + gamma_nl A^2 / 4) / (2 pi), so gamma_nl = 8 pi g
// (JSON width_growth_hz_per_amp2). Each output adds the term's value as `gamma_nl_term`.
#pragma once

#include <cmath>

namespace cvg_bench {

/// gamma_nl of the model term per ring-down gamma_nl (amplitude decay rate per A^2).
inline constexpr double kGammaNlTermPerRingdownRate = 8.0;
/// gamma_nl of the model term per response width growth [Hz per A^2].
inline constexpr double kGammaNlTermPerWidthGrowthHz = 8.0 * M_PI;

}  // namespace cvg_bench
