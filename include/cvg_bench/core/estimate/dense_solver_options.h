// The one Ceres solver setup of the core's small dense fits: Levenberg-Marquardt, dense QR (never
// the normal equations), silent, one thread. The output-error refinement (ceres_refinement.cpp),
// the ring-down fits (numeric_least_squares.cpp) and the one-mode response fits
// (single_mode/response_fit.cpp) take it and set only their stopping rules.
#pragma once

#include <ceres/solver.h>

namespace cvg_bench {

/// Stopping rules of a fit: Ceres' relative decrease of the cost, relative step and gradient norm.
struct DenseSolverStop {
  int max_iterations = 50;
  double function_tolerance = 1e-6;  // Ceres' defaults
  double parameter_tolerance = 1e-8;
  double gradient_tolerance = 1e-10;
};

/// Dense-QR Levenberg-Marquardt options, silent and single-threaded, with the given stopping rules.
ceres::Solver::Options denseSolverOptions(const DenseSolverStop& stop);

}  // namespace cvg_bench
