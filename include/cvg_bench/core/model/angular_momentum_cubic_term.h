// The second isotropic cubic invariant of a 2-D oscillator (beyond the paper; docs/paper.md
// "The second cubic invariant").
//
// The first-order average of any isotropic, conservative cubic force in (f, g) lies in a
// two-dimensional space. The paper's xi (f^2 + g^2) f spans one direction: it sets both the
// amplitude-frequency law (chi' of (5.10)) and the pattern precession xi~ r k / 8 of (5.9), with a
// fixed ratio. `xi_k` spans the other: a gyroscopic force proportional to the angular momentum
// l = f g' - g f',
//   F_f = -(xi_k~ / (2 omega)) l g',  F_g = +(xi_k~ / (2 omega)) l f'
// (xi_k~ in the units of xi~, 1/(s amplitude^2), stored under the plain name `xi_k`), a force
// which does no work (F . v = 0). Averaged, l = omega (q1 p2 - p1 q2) = omega r k, and
//   2 (q1', p1', q2', p2') = (xi_k~ r k / 2) (-q2, -p2, q1, p1),
// a pure rotation of the pattern: theta' = xi_k~ r k / 8, with r, k and chi unchanged. So in the
// extended model theta' = (xi~ + xi_k~) r k / 8 while the amplitude-frequency law depends on xi~
// alone.
#pragma once

#include "cvg_bench/core/model/model_term.h"

namespace cvg_bench {

/// `xi_k`: the angular-momentum cubic term above.
ModelTermPtr makeAngularMomentumCubicTerm();

/// The averaged cubic coefficients of a spherical pendulum of the given length (f, g = horizontal
/// bob displacement in metres, omega^2 = g / length). Its cubic force
///   (omega^2 / (2 L^2)) (f^2 + g^2) x - (1 / L^2) |x'|^2 x
/// averages to xi~ = omega / (6 L^2) and xi_k~ = 8 xi~: the frequency law omega (1 - a^2 / (16
/// L^2)) and Airy's precession of the swing plane 2 theta' = (3/8) omega a b / L^2 (a, b the
/// ellipse's semi-axes).
struct PendulumCubic {
  double xi = 0.0;    ///< xi~ [1/(s m^2)]
  double xi_k = 0.0;  ///< xi_k~ [1/(s m^2)]
};
PendulumCubic sphericalPendulumCubic(double omega_rad_s, double length_m);

}  // namespace cvg_bench
