// Orbit elements of section 5: r (main wave amplitude), k (quadrature amplitude), theta (wave
// pattern angle) and chi (temporal phase), by the change of variables (5.2). Their averaged
// evolution (5.7)-(5.10) of any model comes from the model's own equations
// (orbit_rates_chain_rule.h); the paper's printed closed form, with the corrections of
// docs/paper.md items 4-5, is the tests' known answer (test/core/model/paper_orbit_rates.h), so no
// term's name is spelled here.
#pragma once

#include <Eigen/Core>

#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

struct OrbitElements {
  double r = 0.0;      ///< main wave amplitude, r >= |k| (record amplitude units)
  double k = 0.0;      ///< quadrature amplitude (same units; signed)
  double theta = 0.0;  ///< wave pattern angle [rad], in (-pi/4, pi/4] (defined modulo pi/2)
  double chi = 0.0;    ///< temporal phase [rad]
};

/// (5.2): q = (q1, p1, q2, p2) from the orbit elements.
Eigen::Vector4d slowFromOrbit(const OrbitElements& e);

/// Inverse of (5.2) with the convention r >= |k|, r >= 0:
///   (r^2 - k^2) cos 4 theta = q1^2 + p1^2 - q2^2 - p2^2,  (r^2 - k^2) sin 4 theta = 2 (q1 q2 + p1
///   p2), r^2 + k^2 = |q|^2,  r k = q1 p2 - p1 q2.
/// At r = |k| (a travelling wave) theta is undefined and 0 is returned.
OrbitElements orbitFromSlow(const Eigen::Vector4d& q);

/// The defect moduli and axes of section 2: h_c = h_m cos 4 alpha, h_s = h_m sin 4 alpha,
/// b_c = b_m cos 4 beta, b_s = b_m sin 4 beta.
struct DefectAxes {
  double h_m = 0.0;    ///< frequency-split modulus (tilde) [1/s]
  double alpha = 0.0;  ///< stiffness axis angle [rad], atan2(h_s, h_c) / 4
  double b_m = 0.0;    ///< damping-anisotropy modulus [1/s]
  double beta = 0.0;   ///< damping axis angle [rad], atan2(b_s, b_c) / 4
};
DefectAxes defectAxes(const ParameterValues& p);

/// Rates of the orbit elements [1/s, 1/s, rad/s, rad/s] (orbit_rates_chain_rule.h).
struct OrbitRates {
  double r_dot = 0.0, k_dot = 0.0, theta_dot = 0.0, chi_dot = 0.0;
};

/// Most points a pattern-angle grid may have.
constexpr long kMaxThetaGridPoints = 100000;
/// n pattern angles theta_i = (pi / 2) i / n, i = 0..n-1, evenly over one period [0, pi/2) of the
/// drift (5.9) in theta. InputError unless 1 <= n <= kMaxThetaGridPoints.
std::vector<double> thetaGrid(long n);

}  // namespace cvg_bench
