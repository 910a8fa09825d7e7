// Complex products for the model terms' polynomial forms without the C99 Annex G infinity/NaN
// recovery of std::complex operator* (a branch and possible library call per product): the
// operands are finite polynomials of finite samples, where both give the same value.
#pragma once

#include <complex>

namespace cvg_bench {

/// x y
inline std::complex<double> mul(const std::complex<double>& x, const std::complex<double>& y) {
  return {x.real() * y.real() - x.imag() * y.imag(), x.real() * y.imag() + x.imag() * y.real()};
}

/// i x
inline std::complex<double> timesI(const std::complex<double>& x) {
  return {-x.imag(), x.real()};
}

}  // namespace cvg_bench
