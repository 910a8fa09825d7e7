#include "cvg_bench/core/estimate/output_error_forced.h"

#include <Eigen/LU>

namespace cvg_bench {

ForcedPointOutputError::ForcedPointOutputError(const ResonatorModel& model, double detuning_rate,
                                               const Eigen::Vector4d& q_measured, bool estimate_mu,
                                               double known_mu,
                                               const StationarySolverOptions& options)
    : model_(model),
      detuning_rate_(detuning_rate),
      q_measured_(q_measured),
      estimate_mu_(estimate_mu),
      known_mu_(known_mu),
      options_(options) {
  set_num_residuals(4);
  mutable_parameter_block_sizes()->push_back(model.numParameters());
  if (estimate_mu) mutable_parameter_block_sizes()->push_back(1);
}

StationaryPoint ForcedPointOutputError::modelPoint(const Eigen::VectorXd& z, double mu) const {
  const SlowContext ctx{0.0, mu};
  StationaryPoint best =
      solveStationaryPoint(model_, z, ctx, detuning_rate_, q_measured_, options_);
  if (has_last_solution_) {
    const StationaryPoint cont =
        solveStationaryPoint(model_, z, ctx, detuning_rate_, last_solution_, options_);
    if (cont.converged &&
        (!best.converged || (cont.q - q_measured_).norm() < (best.q - q_measured_).norm())) {
      best = cont;
    }
  }
  if (best.converged) {
    last_solution_ = best.q;
    has_last_solution_ = true;
  }
  return best;
}

bool ForcedPointOutputError::Evaluate(double const* const* parameters, double* residuals,
                                      double** jacobians) const {
  const int k = model_.numParameters();
  const Eigen::VectorXd z = Eigen::Map<const Eigen::VectorXd>(parameters[0], k);
  const double mu = estimate_mu_ ? parameters[1][0] : known_mu_;
  if (!z.allFinite() || !std::isfinite(mu)) return false;
  const StationaryPoint p = modelPoint(z, mu);
  if (!p.converged) return false;
  Eigen::Map<Eigen::Vector4d> r(residuals);
  r = p.q - q_measured_;
  if (jacobians == nullptr) return true;
  const Eigen::FullPivLU<Eigen::Matrix4d> lu(p.jacobian);
  if (jacobians[0] != nullptr) {
    const Eigen::MatrixXd d = model_.regressor(p.q, SlowContext{0.0, mu});
    Eigen::Map<Eigen::Matrix<double, 4, Eigen::Dynamic, Eigen::RowMajor>> j_z(jacobians[0], 4, k);
    j_z = -lu.solve(d);
  }
  if (estimate_mu_ && jacobians[1] != nullptr) {
    const Eigen::MatrixXd d1 = model_.regressor(p.q, SlowContext{0.0, 1.0});
    const Eigen::MatrixXd d0 = model_.regressor(p.q, SlowContext{0.0, 0.0});
    Eigen::Map<Eigen::Vector4d> j_mu(jacobians[1]);
    j_mu = -lu.solve((d1 - d0) * z);
  }
  return true;
}

}  // namespace cvg_bench
