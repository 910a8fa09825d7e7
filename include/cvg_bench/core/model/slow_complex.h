// Complex form of the slow variables used by the nonlinear terms' averaging:
// a = q1 + i p1, b = q2 + i p2 (so f = Re(a e^{-i omega t}), g = Re(b e^{-i omega t}) by (2.4)),
// N = |a|^2 + |b|^2, S = a^2 + b^2. A term whose averaged rate is 2 a' = A, 2 b' = B writes
// (Re A, Im A, Re B, Im B) as its column of D.
#pragma once

#include <Eigen/Core>
#include <complex>

namespace cvg_bench {

struct SlowComplex {
  std::complex<double> a, b;
  double n_sq;             // N = |a|^2 + |b|^2
  std::complex<double> s;  // S = a^2 + b^2

  explicit SlowComplex(const Eigen::Vector4d& q)
      : a(q[0], q[1]), b(q[2], q[3]), n_sq(std::norm(a) + std::norm(b)), s(a * a + b * b) {}
};

/// Writes the column (Re A, Im A, Re B, Im B).
inline void setComplexColumn(const std::complex<double>& two_a_dot,
                             const std::complex<double>& two_b_dot,
                             Eigen::Ref<Eigen::MatrixXd> cols, int col) {
  cols(0, col) = two_a_dot.real();
  cols(1, col) = two_a_dot.imag();
  cols(2, col) = two_b_dot.real();
  cols(3, col) = two_b_dot.imag();
}

}  // namespace cvg_bench
