// Factories of the individual model terms (one file each under src/core/, with its derivation).
#pragma once

#include "cvg_bench/core/model/angular_momentum_cubic_term.h"  // xi_k
#include "cvg_bench/core/model/model_term.h"

namespace cvg_bench {

/// `linear`: the 8 defect parameters of (2.3)/(2.5): gamma, nu, b_c, b_s, c_m, n, h_c, h_s.
ModelTermPtr makeLinearDefectTerm();
/// `controls`: the drive u1..u4 of (3.1)/(3.2), with the known control nonlinearity mu.
ModelTermPtr makeControlTerm();
/// `xi`: cubic stiffness xi (f^2+g^2) f.
ModelTermPtr makeCubicStiffnessTerm();
/// `kappa`: quintic stiffness kappa (f^2+g^2)^2 f.
ModelTermPtr makeQuinticStiffnessTerm();
/// `gamma_nl`: amplitude-dependent damping -gamma_nl (f^2+g^2) f'.
ModelTermPtr makeNonlinearDampingTerm();
/// `cm_rate`: natural frequency drifting linearly in time, c_m(t) = c_m + cm_rate t.
ModelTermPtr makeFrequencyDriftTerm();
/// `xi_diff`: unequal cubic stiffness of the two axes, +xi_diff N f in the f equation, -xi_diff N g
/// in g.
ModelTermPtr makeAxisCubicMismatchTerm();

}  // namespace cvg_bench
