// Small nonlinear least squares over a residual function, solved by Ceres (Levenberg-Marquardt,
// dense QR, central-difference Jacobian): the ring-down fits (ringdown_fit.cpp) and the detector
// filter's correlation fit (ringdown_filter.cpp) use it instead of hand-written loops.
#pragma once

#include <Eigen/Core>
#include <functional>

namespace cvg_bench {

/// Residuals r(p) of a fixed length; false where they cannot be evaluated (e.g. a rate <= 0), which
/// the solver treats as a rejected step.
using ResidualFunction = std::function<bool(const Eigen::VectorXd& p, Eigen::VectorXd& r)>;

/// The Jacobian dr/dp at p by central differences with the step h_k = 1e-6 (1 + |p_k|): absolute
/// near 0, where a relative step vanishes for an offset or a rate that passes close to 0. False
/// where r cannot be evaluated at a step, or is not finite or changes length there.
bool centralDifferenceJacobian(const ResidualFunction& residuals, const Eigen::VectorXd& p,
                               Eigen::MatrixXd& J);

/// Minimizes |r(p)|^2 from p (updated in place); sse = |r(p)|^2 at the returned p. False when the
/// start cannot be evaluated (p and sse unchanged); otherwise the lowest point evaluated, also when
/// Ceres stops at the iteration limit or with FAILURE (a Jacobian that cannot be evaluated). The
/// Jacobian is centralDifferenceJacobian's.
bool minimizeSumOfSquares(const ResidualFunction& residuals, Eigen::VectorXd& p, double& sse,
                          int max_iterations = 100);

}  // namespace cvg_bench
