// Quantiles for the confidence intervals (2.11).
#pragma once

namespace cvg_bench {

/// Two-sided quantile s_p of (2.11): the Student-t quantile of order p = (1 + P0) / 2 with dof
/// degrees of freedom (Boost.Math); dof <= 0 gives the normal quantile (the paper's "Laplace
/// table" for large n - k). P0 must lie in (0, 1) (InputError otherwise).
double studentQuantile(double confidence, int dof);

}  // namespace cvg_bench
