// Nonlinear least squares over a residual function by Ceres (see numeric_least_squares.h).
#include "cvg_bench/core/estimate/numeric_least_squares.h"

#include <ceres/ceres.h>

#include <cmath>

#include "cvg_bench/core/estimate/dense_solver_options.h"

namespace cvg_bench {
namespace {

/// The residual function as a Ceres cost with centralDifferenceJacobian's Jacobian (Ceres' own
/// numeric differentiation takes a relative step).
class FunctionCost : public ceres::CostFunction {
 public:
  FunctionCost(const ResidualFunction* fn, int n_params, int n_residuals, Eigen::VectorXd* best_p,
               double* best_sse)
      : fn_(fn), best_p_(best_p), best_sse_(best_sse) {
    mutable_parameter_block_sizes()->push_back(n_params);
    set_num_residuals(n_residuals);
  }
  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    const int k = parameter_block_sizes()[0], n = num_residuals();
    Eigen::VectorXd p = Eigen::Map<const Eigen::VectorXd>(x[0], k), r;
    if (!eval(p, r)) return false;
    Eigen::Map<Eigen::VectorXd>(residuals, n) = r;
    // The lowest point evaluated: Ceres hands back its start when it stops with FAILURE (e.g. a
    // Jacobian that cannot be evaluated next to a refused region), a loop keeps its progress.
    if (r.squaredNorm() < *best_sse_) *best_sse_ = r.squaredNorm(), *best_p_ = p;
    if (jacobians == nullptr || jacobians[0] == nullptr) return true;
    Eigen::MatrixXd J;
    if (!centralDifferenceJacobian(*fn_, p, J) || J.rows() != n) return false;
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(jacobians[0],
                                                                                       n, k) = J;
    return true;
  }

 private:
  bool eval(const Eigen::VectorXd& p, Eigen::VectorXd& r) const {
    return (*fn_)(p, r) && r.size() == num_residuals() && r.allFinite();
  }
  const ResidualFunction* fn_;
  Eigen::VectorXd* best_p_;
  double* best_sse_;
};

}  // namespace

bool centralDifferenceJacobian(const ResidualFunction& residuals, const Eigen::VectorXd& p,
                               Eigen::MatrixXd& J) {
  Eigen::VectorXd rp, rm;
  for (int c = 0; c < p.size(); ++c) {
    const double h = 1e-6 * (1.0 + std::fabs(p(c)));
    Eigen::VectorXd pp = p, pm = p;
    pp(c) += h;
    pm(c) -= h;
    if (!residuals(pp, rp) || !residuals(pm, rm) || rp.size() != rm.size() ||
        (c > 0 && rp.size() != J.rows()) || !rp.allFinite() || !rm.allFinite())
      return false;
    if (c == 0) J.resize(rp.size(), p.size());
    J.col(c) = (rp - rm) / (2.0 * h);
  }
  return true;
}

bool minimizeSumOfSquares(const ResidualFunction& residuals, Eigen::VectorXd& p, double& sse,
                          int max_iterations) {
  Eigen::VectorXd r;
  if (p.size() == 0 || !residuals(p, r) || r.size() == 0 || !r.allFinite()) return false;
  const int n = static_cast<int>(r.size());
  const int k = static_cast<int>(p.size());
  Eigen::VectorXd best_p = p;
  double best_sse = r.squaredNorm();
  // A relative decrease of 1e-10 moves an estimate by ~1e-5 sqrt(n) of its standard error.
  const ceres::Solver::Options o = denseSolverOptions({max_iterations, 1e-10, 1e-12, 1e-14});
  // Ceres stops with FAILURE where a Jacobian cannot be evaluated (next to a refused region) and
  // hands back its start: solved again from the lowest point seen while that still improves it,
  // as a Levenberg-Marquardt loop would go on from there.
  for (int round = 0; round < 8; ++round) {
    const double start_sse = best_sse;
    std::vector<double> x(best_p.data(), best_p.data() + k);
    ceres::Problem problem;
    problem.AddResidualBlock(new FunctionCost(&residuals, k, n, &best_p, &best_sse), nullptr,
                             x.data());
    ceres::Solver::Summary summary;
    ceres::Solve(o, &problem, &summary);
    const Eigen::VectorXd solved = Eigen::Map<const Eigen::VectorXd>(x.data(), k);
    Eigen::VectorXd rs;
    if (residuals(solved, rs) && rs.size() == n && rs.allFinite() && rs.squaredNorm() <= best_sse) {
      best_p = solved;
      best_sse = rs.squaredNorm();
    }
    if (summary.termination_type != ceres::FAILURE || !(best_sse < start_sse * (1.0 - 1e-10)))
      break;
  }
  p = best_p;
  sse = best_sse;
  return true;
}

}  // namespace cvg_bench
