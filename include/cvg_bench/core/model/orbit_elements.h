// Orbit elements of section 5: r (main wave amplitude), k (quadrature amplitude), theta (wave
// pattern angle) and chi (temporal phase), by the change of variables (5.2), and their averaged
// evolution (5.7)-(5.10) with the corrections of docs/paper.md item 4-5: the nonlinear terms carry
// the tilde coefficients, and the damping-anisotropy terms depend on (theta - beta).
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

struct OrbitRates {
  double r_dot = 0.0, k_dot = 0.0, theta_dot = 0.0, chi_dot = 0.0;
};

/// (5.7)-(5.10) (corrected) for free oscillation (u = 0) with the paper's terms gamma, nu, b_c,
/// b_s, c_m, n, h_c, h_s, xi, kappa and the second cubic invariant xi_k (theta' only) taken from p
/// (missing ones are 0). Requires r^2 != k^2.
OrbitRates orbitRates(const OrbitElements& e, const ParameterValues& p);

/// The drift rate theta' of (5.9) [rad/s] (corrected; plus xi_k r k / 8), the gyro's zero-rate
/// error at (r, k, theta).
double driftRate(double r, double k, double theta, const ParameterValues& p);

/// Most points a pattern-angle grid may have.
constexpr long kMaxThetaGridPoints = 100000;
/// n pattern angles theta_i = (pi / 2) i / n, i = 0..n-1, evenly over one period [0, pi/2) of the
/// drift (5.9) in theta. InputError unless 1 <= n <= kMaxThetaGridPoints.
std::vector<double> thetaGrid(long n);

}  // namespace cvg_bench
