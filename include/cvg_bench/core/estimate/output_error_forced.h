// Output-error residual of one point of a forced sweep (section 3) for Ceres.
//
// The model point is the stationary solution q*(z, mu) of (3.3), F(q) = D(q; mu) z - rate y(q) = 0
// (stationary_solver.h), and the residual is r = q* - q_measured (4 residuals, units of q).
// Derivatives are analytic by the implicit function theorem, dF/dq dq* + dF/dp = 0:
//   dq*/dz  = -(dF/dq)^-1 D(q*)                         (F is linear in z),
//   dq*/dmu = -(dF/dq)^-1 (D(q*; 1) - D(q*; 0)) z        (D is linear in mu, (3.2)),
// with dF/dq by central differences of the model. Branch choice: Newton is started from the
// measured point and from this point's previous solution; the converged solution nearer the
// measured point is used (the model point of the branch the measurement lies on). Evaluate fails
// (Ceres then rejects the step) when neither converges.
// Not thread-safe (a per-point cache of the last solution); Ceres runs it single-threaded.
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include "cvg_bench/core/model/resonator_model.h"
#include "cvg_bench/core/model/stationary_solver.h"

namespace cvg_bench {

class ForcedPointOutputError : public ceres::CostFunction {
 public:
  /// Parameter blocks: z [model.numParameters()] and, when estimate_mu, mu [1]; otherwise mu is
  /// fixed at known_mu. model must outlive the cost function.
  ForcedPointOutputError(const ResonatorModel& model, double detuning_rate,
                         const Eigen::Vector4d& q_measured, bool estimate_mu, double known_mu,
                         const StationarySolverOptions& options);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  /// The model's stationary point at the given parameters (same branch rule as Evaluate).
  StationaryPoint modelPoint(const Eigen::VectorXd& z, double mu) const;

 private:
  const ResonatorModel& model_;
  double detuning_rate_;
  Eigen::Vector4d q_measured_;
  bool estimate_mu_;
  double known_mu_;
  StationarySolverOptions options_;
  mutable Eigen::Vector4d last_solution_;
  mutable bool has_last_solution_ = false;
};

}  // namespace cvg_bench
