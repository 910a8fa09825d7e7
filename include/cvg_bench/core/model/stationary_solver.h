// Stationary points of the forced averaged equations (3.3): q' = 0, i.e.
//   F(q) = D(q) z - rate y(q) = 0,   rate = detuningRate(omega, omega0),  y = detuningDirection(q),
// solved by damped Newton. The Jacobian dF/dq is taken by central differences of the model's own
// right-hand side (ResonatorModel::slowDerivative), so every term of the model is covered.
// Near a fold of the response curve (bistable nonlinear resonance) dF/dq is singular and Newton
// may stop or jump to the other branch: the result says so instead of returning garbage.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

struct StationarySolverOptions {
  /// Maximum Newton iterations, >= 1.
  int max_iterations = 60;
  /// Convergence: Newton step norm <= step_tolerance * max(|q|, q_scale), in (0, 1).
  double step_tolerance = 1e-13;
  /// Amplitude scale for the convergence test and the difference step [amplitude units], > 0.
  double q_scale = 1e-3;
  /// Relative step of the central differences of dF/dq, in (0, 1).
  double difference_step = 1e-6;
  /// Reciprocal condition number of dF/dq below which the point is called a fold, in (0, 1).
  double min_reciprocal_condition = 1e-12;

  /// Every problem with the options, empty when valid.
  std::vector<std::string> validate() const;
};

struct StationaryPoint {
  Eigen::Vector4d q = Eigen::Vector4d::Zero();         ///< stationary (q1, p1, q2, p2)
  Eigen::Matrix4d jacobian = Eigen::Matrix4d::Zero();  ///< dF/dq at q
  bool converged = false;
  int iterations = 0;
  double residual_norm = 0.0;  ///< |F(q)| [1/s x amplitude]
  std::string failure;         ///< why not converged (empty when converged)
};

/// F(q) = D(q) z - rate y(q) = 2 q' of (3.3).
Eigen::Vector4d stationaryResidual(const ResonatorModel& model, const Eigen::Vector4d& q,
                                   const SlowContext& ctx, const Eigen::VectorXd& z,
                                   double detuning_rate);

/// dF/dq by central differences (step difference_step * max(|q|, q_scale)).
Eigen::Matrix4d stationaryJacobian(const ResonatorModel& model, const Eigen::Vector4d& q,
                                   const SlowContext& ctx, const Eigen::VectorXd& z,
                                   double detuning_rate,
                                   const StationarySolverOptions& options = {});

/// Damped Newton from q_start. Never throws on non-convergence (see StationaryPoint::failure);
/// InputError for invalid options or non-finite inputs.
StationaryPoint solveStationaryPoint(const ResonatorModel& model, const Eigen::VectorXd& z,
                                     const SlowContext& ctx, double detuning_rate,
                                     const Eigen::Vector4d& q_start,
                                     const StationarySolverOptions& options = {});

}  // namespace cvg_bench
