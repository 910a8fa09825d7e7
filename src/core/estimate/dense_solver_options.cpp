// The one Ceres solver setup of the core's small dense fits (see dense_solver_options.h).
#include "cvg_bench/core/estimate/dense_solver_options.h"

namespace cvg_bench {

ceres::Solver::Options denseSolverOptions(const DenseSolverStop& stop) {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::DENSE_QR;
  o.max_num_iterations = stop.max_iterations;
  o.function_tolerance = stop.function_tolerance;
  o.parameter_tolerance = stop.parameter_tolerance;
  o.gradient_tolerance = stop.gradient_tolerance;
  o.logging_type = ceres::SILENT;
  o.minimizer_progress_to_stdout = false;
  o.num_threads = 1;
  return o;
}

}  // namespace cvg_bench
