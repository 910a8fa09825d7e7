// The AR(1) coefficient of the noise behind a least-squares fit's residuals, corrected for what
// the fit removes (for the correlation-honest intervals of the output-error fit).
//
// With n residual rows, `channels` interleaved per time step (row t and t - channels are one step
// apart), Jacobian J, C = (J'J)^+ and hat matrix H = J C J', the residuals are r = (I - H) e. For
// noise e with Sigma_ij = rho^|steps between i and j| on the same channel,
//   E[r'r]     = n - tr(C S),                          S = J' Sigma J,
//   E[r'L r]   = (n - channels) rho - 2 tr(C A) + tr(B C S C),
// L the symmetrised one-step shift, A = sym(J' Sigma L J), B = J' L J. The fit removes mostly
// slow (low-frequency) noise, so the residuals' lag-1 correlation r'Lr / r'r falls below rho
// (AR(1) rho = 0.9 on ~10^3 samples with ~10 unknowns: ~0.87, i.e. ~15 % too narrow intervals).
// rho is the root of E[r'Lr] / E[r'r] = the observed lag-1 correlation (bisection). The lag sums
// enter only as M_0, M_1 and sum_d rho^d M_d, M_d = sum_i J_{i+cd}' J_i: formed lag by lag on
// small problems (rows x lags <= 2e7), else by one backward recursion over J per rho (O(n p^2)
// whatever the number of lags; the same sums up to rounding).
#pragma once

#include <Eigen/Core>

namespace cvg_bench {

/// rho in [observed_lag1, 1 - (1 - observed_lag1) / 2] (the observed value when J has no rows to
/// spare or observed_lag1 <= 0). c: (J'J)^+ in the units of j.
double fittedResidualAr1(const Eigen::MatrixXd& j, const Eigen::MatrixXd& c, int channels,
                         double observed_lag1);

/// The same expectation for a given rho, always by the recursion (exposed for tests):
/// E[r'Lr] / E[r'r].
double expectedResidualLag1(const Eigen::MatrixXd& j, const Eigen::MatrixXd& c, int channels,
                            double rho);

}  // namespace cvg_bench
