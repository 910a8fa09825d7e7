#include "cvg_bench/core/model/stationary_solver.h"

#include <Eigen/LU>
#include <cmath>
#include <sstream>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {

std::vector<std::string> StationarySolverOptions::validate() const {
  std::vector<std::string> problems;
  if (max_iterations < 1) problems.push_back("stationary max_iterations must be >= 1");
  if (!(step_tolerance > 0 && step_tolerance < 1))
    problems.push_back("stationary step_tolerance must be in (0, 1)");
  if (!(q_scale > 0 && std::isfinite(q_scale)))
    problems.push_back("stationary q_scale must be finite and > 0");
  if (!(difference_step > 0 && difference_step < 1))
    problems.push_back("stationary difference_step must be in (0, 1)");
  if (!(min_reciprocal_condition > 0 && min_reciprocal_condition < 1))
    problems.push_back("stationary min_reciprocal_condition must be in (0, 1)");
  return problems;
}

Eigen::Vector4d stationaryResidual(const ResonatorModel& model, const Eigen::Vector4d& q,
                                   const SlowContext& ctx, const Eigen::VectorXd& z,
                                   double detuning_rate) {
  return 2.0 * model.slowDerivative(q, ctx, z, detuning_rate);
}

Eigen::Matrix4d stationaryJacobian(const ResonatorModel& model, const Eigen::Vector4d& q,
                                   const SlowContext& ctx, const Eigen::VectorXd& z,
                                   double detuning_rate, const StationarySolverOptions& options) {
  const double h = options.difference_step * std::max(q.norm(), options.q_scale);
  Eigen::Matrix4d j;
  for (int c = 0; c < 4; ++c) {
    Eigen::Vector4d qp = q, qm = q;
    qp[c] += h;
    qm[c] -= h;
    j.col(c) = (stationaryResidual(model, qp, ctx, z, detuning_rate) -
                stationaryResidual(model, qm, ctx, z, detuning_rate)) /
               (2 * h);
  }
  return j;
}

StationaryPoint solveStationaryPoint(const ResonatorModel& model, const Eigen::VectorXd& z,
                                     const SlowContext& ctx, double detuning_rate,
                                     const Eigen::Vector4d& q_start,
                                     const StationarySolverOptions& options) {
  const auto problems = options.validate();
  if (!problems.empty()) throw InputError(problems.front());
  if (!q_start.allFinite() || !z.allFinite() || !std::isfinite(detuning_rate) ||
      !std::isfinite(ctx.mu))
    throw InputError("stationary solve: non-finite start, parameters or detuning");
  StationaryPoint p;
  p.q = q_start;
  Eigen::Vector4d f = stationaryResidual(model, p.q, ctx, z, detuning_rate);
  for (p.iterations = 1; p.iterations <= options.max_iterations; ++p.iterations) {
    p.jacobian = stationaryJacobian(model, p.q, ctx, z, detuning_rate, options);
    const Eigen::FullPivLU<Eigen::Matrix4d> lu(p.jacobian);
    if (!p.jacobian.allFinite() || lu.rcond() < options.min_reciprocal_condition) {
      p.failure = "singular dF/dq (fold of the response curve) at q = (" + std::to_string(p.q[0]) +
                  ", " + std::to_string(p.q[1]) + ", " + std::to_string(p.q[2]) + ", " +
                  std::to_string(p.q[3]) + ")";
      p.residual_norm = f.norm();
      return p;
    }
    const Eigen::Vector4d step = -lu.solve(f);
    if (step.norm() <= options.step_tolerance * std::max(p.q.norm(), options.q_scale)) {
      p.q += step;
      p.converged = true;
      p.residual_norm = stationaryResidual(model, p.q, ctx, z, detuning_rate).norm();
      p.jacobian = stationaryJacobian(model, p.q, ctx, z, detuning_rate, options);
      return p;
    }
    // Backtracking on |F| keeps the iteration from running off near a fold.
    double alpha = 1.0;
    bool reduced = false;
    for (int k = 0; k < 30 && !reduced; ++k, alpha *= 0.5) {
      const Eigen::Vector4d q_new = p.q + alpha * step;
      const Eigen::Vector4d f_new = stationaryResidual(model, q_new, ctx, z, detuning_rate);
      if (f_new.allFinite() && f_new.norm() <= (1 - 1e-4 * alpha) * f.norm()) {
        p.q = q_new;
        f = f_new;
        reduced = true;
      }
    }
    if (!reduced) {
      p.residual_norm = f.norm();
      p.failure = "Newton line search found no decrease of |F| (near a fold?)";
      return p;
    }
  }
  p.residual_norm = f.norm();
  std::ostringstream s;
  s << "Newton did not converge in " << options.max_iterations
    << " iterations (|F| = " << p.residual_norm << ")";
  p.failure = s.str();
  return p;
}

}  // namespace cvg_bench
