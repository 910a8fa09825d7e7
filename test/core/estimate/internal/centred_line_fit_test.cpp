// Known answers of the shared line-fit kernel (estimate/internal/centred_line_fit.h).
#include "cvg_bench/core/estimate/internal/centred_line_fit.h"

#include <gtest/gtest.h>

#include <vector>

namespace cvg_bench {
namespace {

TEST(CentredLineFit, AnExactLineIsRecoveredWithZeroResiduals) {
  const std::vector<double> x = {1.0, 2.0, 4.0, 7.0};
  std::vector<double> y;
  for (double v : x) y.push_back(2.0 - 3.0 * v);
  const CentredLineFit f = centredLineFit(x.data(), y.data(), x.size());
  EXPECT_NEAR(f.slope, -3.0, 1e-14);
  EXPECT_NEAR(f.x_mean, 3.5, 1e-15);
  EXPECT_NEAR(f.y_mean, 2.0 - 3.0 * 3.5, 1e-14);
  EXPECT_NEAR(f.sxx, 2.5 * 2.5 + 1.5 * 1.5 + 0.5 * 0.5 + 3.5 * 3.5, 1e-13);
  for (size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(f.residual(x[i], y[i]), 0.0, 1e-13);
}

TEST(CentredLineFit, ScatterAboutALineGivesTheLeastSquaresSlope) {
  // Four points off a line: slope sxy / sxx about the means (1.5, 1.5).
  const std::vector<double> x = {0.0, 1.0, 2.0, 3.0}, y = {1.0, 0.0, 1.0, 4.0};
  const CentredLineFit f = centredLineFit(x.data(), y.data(), x.size());
  EXPECT_NEAR(f.slope, 1.0, 1e-14);  // sxy = 5, sxx = 5
  EXPECT_NEAR(f.residual(3.0, 4.0), 1.0, 1e-14);
  EXPECT_NEAR(f.residual(1.0, 0.0), -1.0, 1e-14);
}

TEST(CentredLineFit, EqualAbscissasHaveNoSlope) {
  const std::vector<double> x = {2.0, 2.0, 2.0}, y = {1.0, 5.0, 3.0};
  const CentredLineFit f = centredLineFit(x.data(), y.data(), x.size());
  EXPECT_EQ(f.sxx, 0.0);
  EXPECT_EQ(f.slope, 0.0);
  EXPECT_NEAR(f.y_mean, 3.0, 1e-15);
}

}  // namespace
}  // namespace cvg_bench
