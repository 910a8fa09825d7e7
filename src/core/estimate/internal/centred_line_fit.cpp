#include "cvg_bench/core/estimate/internal/centred_line_fit.h"

namespace cvg_bench {

CentredLineFit centredLineFit(const double* x, const double* y, std::size_t n) {
  CentredLineFit f;
  for (std::size_t i = 0; i < n; ++i) f.x_mean += x[i], f.y_mean += y[i];
  f.x_mean /= static_cast<double>(n);
  f.y_mean /= static_cast<double>(n);
  double sxy = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    f.sxx += (x[i] - f.x_mean) * (x[i] - f.x_mean);
    sxy += (x[i] - f.x_mean) * (y[i] - f.y_mean);
  }
  if (f.sxx > 0.0) f.slope = sxy / f.sxx;
  return f;
}

}  // namespace cvg_bench
