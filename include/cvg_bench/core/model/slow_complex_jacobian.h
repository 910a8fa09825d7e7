// Jacobians of the complex-form columns of slow_complex.h with respect to q = (q1, p1, q2, p2).
// A column (A, B) = (2 a', 2 b') is a polynomial in a, conj(a), b, conj(b); with its Wirtinger
// derivatives A_a = dA/da, A_ac = dA/d conj(a) (likewise for b), the real derivatives are
//   dA/dq1 = A_a + A_ac,  dA/dp1 = i (A_a - A_ac),  dA/dq2 = A_b + A_bc,  dA/dp2 = i (A_b - A_bc),
// and the Jacobian rows are (Re dA, Im dA, Re dB, Im dB).
#pragma once

#include <Eigen/Core>
#include <complex>

#include "cvg_bench/core/model/complex_product.h"
#include "cvg_bench/core/model/slow_complex.h"

namespace cvg_bench {

/// Wirtinger derivatives of a column (A, B): x_y = dx/dy, suffix c = the conjugate variable.
struct ComplexColumnDerivatives {
  std::complex<double> a_a, a_ac, a_b, a_bc;
  std::complex<double> b_a, b_ac, b_b, b_bc;
};

/// Writes the 4 x 4 real Jacobian of scale x (A, B) (scale complex: the term's coefficient, e.g.
/// i xi~ / 4).
inline void setComplexJacobian(const ComplexColumnDerivatives& d, const std::complex<double>& scale,
                               Eigen::Matrix4d& jacobian) {
  const std::complex<double> cols[2][4] = {
      {d.a_a + d.a_ac, timesI(d.a_a - d.a_ac), d.a_b + d.a_bc, timesI(d.a_b - d.a_bc)},
      {d.b_a + d.b_ac, timesI(d.b_a - d.b_ac), d.b_b + d.b_bc, timesI(d.b_b - d.b_bc)}};
  for (int row = 0; row < 2; ++row) {
    for (int c = 0; c < 4; ++c) {
      const std::complex<double> v = mul(scale, cols[row][c]);
      jacobian(2 * row, c) = v.real();
      jacobian(2 * row + 1, c) = v.imag();
    }
  }
}

/// Derivatives of the cubic-type column A = 2 N a + sigma S conj(a), B = 2 N b + sigma S conj(b)
/// (sigma = +1: cubic stiffness xi and xi_diff; sigma = -1: nonlinear damping gamma_nl).
inline ComplexColumnDerivatives cubicColumnDerivatives(const SlowComplex& z, double sigma) {
  const std::complex<double> a = z.a, b = z.b, ac = std::conj(z.a), bc = std::conj(z.b);
  ComplexColumnDerivatives d;
  d.a_a = 2.0 * z.n_sq + (2.0 + 2.0 * sigma) * std::norm(a);
  d.a_ac = 2.0 * mul(a, a) + sigma * z.s;
  d.a_b = 2.0 * mul(bc, a) + 2.0 * sigma * mul(b, ac);
  d.a_bc = 2.0 * mul(a, b);
  d.b_b = 2.0 * z.n_sq + (2.0 + 2.0 * sigma) * std::norm(b);
  d.b_bc = 2.0 * mul(b, b) + sigma * z.s;
  d.b_a = 2.0 * mul(ac, b) + 2.0 * sigma * mul(a, bc);
  d.b_ac = d.a_bc;
  return d;
}

/// Derivatives of the quintic column A = c0 a + c1 conj(a), B = c0 b + c1 conj(b) with
/// c0 = 2 N^2 + |S|^2, c1 = 2 N S.
inline ComplexColumnDerivatives quinticColumnDerivatives(const SlowComplex& z) {
  const std::complex<double> a = z.a, b = z.b, ac = std::conj(z.a), bc = std::conj(z.b);
  const double n = z.n_sq;
  const std::complex<double> s = z.s, sc = std::conj(z.s);
  const double c0 = 2.0 * n * n + std::norm(s);
  const std::complex<double> c1 = 2.0 * n * s;
  // d c0 and d c1 with respect to a, conj(a), b, conj(b).
  const std::complex<double> c0_a = 4.0 * n * ac + 2.0 * mul(a, sc);
  const std::complex<double> c0_ac = 4.0 * n * a + 2.0 * mul(ac, s);
  const std::complex<double> c0_b = 4.0 * n * bc + 2.0 * mul(b, sc);
  const std::complex<double> c0_bc = 4.0 * n * b + 2.0 * mul(bc, s);
  const std::complex<double> c1_a = 2.0 * mul(ac, s) + 4.0 * n * a, c1_ac = 2.0 * mul(a, s);
  const std::complex<double> c1_b = 2.0 * mul(bc, s) + 4.0 * n * b, c1_bc = 2.0 * mul(b, s);
  ComplexColumnDerivatives d;
  d.a_a = mul(c0_a, a) + c0 + mul(c1_a, ac);
  d.a_ac = mul(c0_ac, a) + mul(c1_ac, ac) + c1;
  d.a_b = mul(c0_b, a) + mul(c1_b, ac);
  d.a_bc = mul(c0_bc, a) + mul(c1_bc, ac);
  d.b_a = mul(c0_a, b) + mul(c1_a, bc);
  d.b_ac = mul(c0_ac, b) + mul(c1_ac, bc);
  d.b_b = mul(c0_b, b) + c0 + mul(c1_b, bc);
  d.b_bc = mul(c0_bc, b) + mul(c1_bc, bc) + c1;
  return d;
}

}  // namespace cvg_bench
