// The result of an identification: what every estimator (batch LS, RLS, Ceres) returns and what the
// tool's JSON, the identifier node's messages and the explain report are made from.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "cvg_bench/core/model/model_term.h"

namespace cvg_bench {

/// One estimated quantity with its standard error and Student-t confidence interval (2.11).
/// In Estimate::parameters the standard error is the HONEST one (see Estimate::interval_method);
/// Estimate::parameters_paper holds the paper's (2.11) for comparison.
struct ParameterEstimate {
  double value = 0.0;
  double std_error = 0.0;  ///< standard error (same unit as value)
  double ci_low = 0.0;     ///< value - s_p * std_error
  double ci_high = 0.0;    ///< value + s_p * std_error
};

/// value +- s_p x standard error with standard error sqrt(variance) (a variance below 0 from
/// rounding counts as 0): the interval form of (2.11), s_p the quantile of the chosen distribution.
inline ParameterEstimate interval(double value, double variance, double s_p) {
  ParameterEstimate p;
  p.value = value;
  p.std_error = std::sqrt(std::max(0.0, variance));
  p.ci_low = value - s_p * p.std_error;
  p.ci_high = value + s_p * p.std_error;
  return p;
}

struct Estimate {
  ExperimentMode mode = ExperimentMode::kFreeDecay;
  std::string model;         ///< canonical spec, e.g. "linear+xi"
  std::string method;        ///< "ls", "rls" or "ceres"
  double omega_rad_s = 0.0;  ///< natural frequency used for tilde quantities [rad/s]
  int n_equations = 0;       ///< equations actually stacked (docs/paper.md item 8)
  int n_params = 0;
  int rank = 0;  ///< numerical rank of the regression matrix
  int dof = 0;   ///< n_equations - rank
  /// Parameters (or combinations, written as e.g. "gamma+b_c") the data cannot separate.
  std::vector<std::string> unidentifiable;
  std::string identifiability_note;  ///< why, in words (empty when full rank)
  double sigma = 0.0;              ///< sigma-hat (2.10), in equation units (docs/paper.md item 14)
  double confidence = 0.95;        ///< P0 of (2.11)
  std::vector<std::string> names;  ///< parameter names in z order
  Eigen::VectorXd values;          ///< z-hat
  Eigen::MatrixXd covariance;      ///< covariance of z-hat (row-major order = names order)
  std::map<std::string, ParameterEstimate> parameters;  ///< by name
  std::map<std::string, ParameterEstimate> derived;     ///< section-4 quantities with CIs
  std::vector<std::string> notes;  ///< provenance: e.g. "demodulated raw f,g at omega = ..."

  // ---- added by the identification (estimators that do not fill them leave them empty)
  /// How `covariance` / `parameters` were obtained, e.g. "sandwich, block MA(2) (free decay)";
  /// "paper (2.11)" when only the paper's form is available.
  std::string interval_method;
  int interval_dof =
      0;  ///< Student-t degrees of freedom of the intervals in `parameters` (0: normal)
  /// The paper's (2.11): sigma-hat^2 (D'D)^-1 and s_p with n - k dof, assuming independent
  /// equation errors (too wide for free decay, docs/paper.md item 10).
  Eigen::MatrixXd covariance_paper;
  std::map<std::string, ParameterEstimate> parameters_paper;
  /// When rank-deficient: the combinations the data do determine (e.g. "gamma+b_c"), with CIs.
  std::map<std::string, ParameterEstimate> combinations;
  /// Singular values of the column-equilibrated regression matrix, descending.
  std::vector<double> singular_values;
  double rank_tolerance = 0.0;  ///< relative singular-value tolerance used for `rank`

  // ---- serial correlation of the residuals and the method of the intervals
  /// Short name of the method behind `parameters`: "eiv_white", "eiv_ar1", "demod_correlation",
  /// "cluster_sandwich", "hac_bartlett_andrews", "iid", "paper_2_11" (empty: not set).
  std::string interval_method_id;
  double residual_lag1 = 0.0;           ///< lag-1 correlation of the residuals (one time step)
  double residual_lag1_expected = 0.0;  ///< its value under independent noise
  double residual_lag1_z = 0.0;         ///< the test statistic (residual_serial_correlation.h)
  bool residual_correlated = false;     ///< |z| > 2.576: the intervals account for it
  std::string noise_model;              ///< e.g. "AR(1) rho = 0.9 (fitted)"

  // ---- near-collinear identifiability (collinearity.h)
  std::map<std::string, double> vif;  ///< variance-inflation factor per parameter
  double condition_number = 0.0;      ///< of the column-normalized Jacobian (0: not computed)
  /// Weakly identified directions: text (column-normalized coefficients) and singular value.
  std::vector<std::pair<std::string, double>> weak_directions;
  /// Parameters the record does not identify (VIF >= 1e4), reported with `combinations`.
  std::vector<std::string> not_identified;
  /// How a derived quantity was obtained where it is not the plain section-4 formula.
  std::map<std::string, std::string> derived_method;
  /// Free decay: c with c'z = the envelope decay rate gamma_env of the record (Q = omega /
  /// gamma_env), in `names` order; empty otherwise.
  Eigen::VectorXd envelope_coefficients;
  /// Free decay, output-error fit: the fitted initial slow variables q(t0) (4 nuisance unknowns,
  /// not parameters); as a refinement's start, where its integration begins. Empty otherwise.
  Eigen::VectorXd initial_slow_state;
};

}  // namespace cvg_bench
