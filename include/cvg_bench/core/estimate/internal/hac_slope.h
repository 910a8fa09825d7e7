// The slope of y on t by least squares (QR) with a HAC (Newey-West) standard error and a Student-t
// interval (n - 2 dof): the rate of a slow variable over a window whose residuals may be serially
// correlated. Shared by the orbit reading and the measured drift (diagnose/).
#pragma once

#include <vector>

#include "cvg_bench/core/estimate/estimate.h"

namespace cvg_bench {

/// All zero when fewer than 6 points.
ParameterEstimate hacSlope(const std::vector<double>& t, const std::vector<double>& y,
                           double confidence);

}  // namespace cvg_bench
