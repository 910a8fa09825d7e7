// Near-collinear identifiability (beyond the exact rank of identifiability.h): how much the other
// columns of the regression / output-error Jacobian leave to each parameter, scale-free. With J_s
// the column-normalized Jacobian (unit column norms, singular values s_i, right vectors v_i), the
// variance-inflation factor VIF_j = [(J_s'J_s)^-1]_jj = sum_i v_ji^2 / s_i^2 is the factor by
// which the other columns inflate the variance of z_j; sqrt(VIF_j) >= 100 (kNotIdentifiedVif)
// means the record pins z_j only through a combination with others, and the parameter is reported
// as "not identified by this record" together with the combinations it does determine.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "cvg_bench/core/estimate/estimate.h"
#include "cvg_bench/core/estimate/identifiability.h"

namespace cvg_bench {

constexpr double kNotIdentifiedVif = 1e4;
/// Singular values of J_s below this are the weakly identified directions named in the report.
constexpr double kWeakSingularValue = 1e-2;

struct WeakDirection {
  std::string text;              ///< e.g. "0.707*n -0.707*b_c" (column-normalized coefficients)
  double singular_value = 0.0;   ///< of J_s
  Eigen::VectorXd coefficients;  ///< the same direction in parameter units (unit norm)
};

struct CollinearityReport {
  std::vector<double> vif;        ///< per column of J
  double condition_number = 1.0;  ///< s_max / s_min of J_s (infinite when rank-deficient)
  std::vector<WeakDirection> weak;
  /// Among the first n_reported names: VIF >= kNotIdentifiedVif.
  std::vector<std::string> not_identified;
  /// The weak directions as columns (parameter units), for analyzeIdentifiability.
  Eigen::MatrixXd weak_space;
  Eigen::VectorXd column_norms;  ///< of J (the normalization)
};

/// jacobian: any matrix whose Gram is J'J (the k x k R factor of the LS system, or the Ceres
/// Jacobian itself), columns named by names; n_reported: leading columns that are model
/// parameters (later ones are nuisance unknowns such as initial states).
CollinearityReport analyzeCollinearity(const std::vector<std::string>& names,
                                       const Eigen::MatrixXd& jacobian, int n_reported);

/// Writes the report into e: vif, condition_number, weak_directions, not_identified, and when
/// some parameter is not identified the combinations of the involved parameters that the record
/// does determine (orthogonal to the weak directions, with intervals at quantile s_p from
/// covariance) and identifiability_note in words. names / values / covariance: all columns of the
/// analysed Jacobian (the model parameters first).
void reportCollinearity(const CollinearityReport& report, const std::vector<std::string>& names,
                        const Eigen::VectorXd& values, const Eigen::MatrixXd& covariance,
                        const ExcitationSummary& excitation, double s_p, Estimate* e);

}  // namespace cvg_bench
