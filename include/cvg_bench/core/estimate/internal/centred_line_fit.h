// The least-squares line through n points in centred form, y = y_mean + slope (x - x_mean): the
// one kernel behind a scatter's slope (diagnose/orbit_reading) and a pass's slope
// (diagnose/drift_measurement). Two parameters on centred data: the closed form is the QR
// solution (the centred columns are orthogonal), with no normal-equation inverse.
#pragma once

#include <cstddef>

namespace cvg_bench {

struct CentredLineFit {
  double x_mean = 0.0, y_mean = 0.0;
  double slope = 0.0;
  double sxx = 0.0;  ///< sum (x - x_mean)^2; 0 when every x is equal (slope then 0)
  double residual(double x, double y) const { return y - y_mean - slope * (x - x_mean); }
};

/// The line through (x[i], y[i]), i < n; n >= 1.
CentredLineFit centredLineFit(const double* x, const double* y, std::size_t n);

}  // namespace cvg_bench
