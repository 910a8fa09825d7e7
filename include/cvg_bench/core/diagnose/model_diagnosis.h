// Statistics of nested model comparison and model adequacy used by `explain`.
//
// Nested test. The equation errors of (2.8) are correlated (docs/paper.md item 10) and those of
// (3.4) are heteroscedastic and correlated within a sweep point, so the classical nested F-test on
// residual sums of squares has the wrong null distribution. The test used is the Wald test on the
// added parameters with the identification's HONEST covariance (Estimate::covariance: sandwich
// with the lag-2 block structure in free decay, per-point clusters in forced mode):
//   W = z_a^T C_aa^{-1} z_a,   F = W / p_a,
// referred to F(p_a, Estimate::interval_dof) when interval_dof > 0, else chi^2(p_a) / p_a.
// Rank-deficient C_aa uses its pseudo-inverse with p_a = its rank.
// delta BIC = n ln(RSS_1 / RSS_0) + (k_1 - k_0) ln n with n equations (reported, not used to
// decide: it assumes independent errors).
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/estimate/estimate.h"

namespace cvg_bench {

struct WaldTestResult {
  double f_statistic = 0.0;  ///< W / df1
  int df1 = 0;               ///< number of tested parameters (rank of their covariance)
  int df2 = 0;               ///< denominator dof (0: chi-square reference)
  double p_value = 1.0;
};

/// Wald test that the named parameters of `extended` are all zero. InputError when a name is not
/// a parameter of the estimate.
WaldTestResult waldTest(const Estimate& extended, const std::vector<std::string>& tested);

/// delta BIC of a nested pair fitted on the same n equations (negative favours the larger model).
double deltaBic(double rss_base, double rss_extended, long n_equations, int added_parameters);

/// Upper-tail p-value of F(df1, df2); df2 <= 0 means chi^2(df1)/df1. Never NaN (1 for bad input).
double fUpperTail(double f, int df1, int df2);

}  // namespace cvg_bench
