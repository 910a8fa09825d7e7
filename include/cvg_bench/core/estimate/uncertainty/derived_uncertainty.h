// Uncertainty of derived quantities by the delta method: var f(z) = J C J', J the numerical
// Jacobian (central differences) of f at z-hat, C the estimate's covariance (the honest one).
//  - section 4's quantities (deriveQuantities);
//  - the drift rate theta' at (r, k, theta) of any model (orbit_rates_chain_rule.h).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "cvg_bench/core/estimate/estimate.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

/// Named values with a covariance over (a subset of) them; dof 0 = normal quantile.
struct UncertainParameters {
  ParameterValues values;
  std::vector<std::string> cov_names;  ///< rows/cols of covariance; empty = no covariance
  Eigen::MatrixXd covariance;
  int dof = 0;
  double confidence = 0.95;
};

/// From an Estimate (values, names, covariance = the honest one, interval_dof, confidence).
UncertainParameters uncertainParameters(const Estimate& e);

/// The gradient of f over the covariance's parameters (cov_names order) by central differences
/// at a small fraction of each standard error; InputError when the covariance's size is wrong.
Eigen::VectorXd deltaMethodGradient(const std::function<double(const ParameterValues&)>& f,
                                    const UncertainParameters& p);

/// Delta-method interval of any scalar function of the named values.
ParameterEstimate deltaMethod(const std::function<double(const ParameterValues&)>& f,
                              const UncertainParameters& p);

/// Section 4's derived quantities with CIs (keys of DerivedQuantities::asMap()).
std::map<std::string, ParameterEstimate> deriveQuantitiesWithIntervals(const UncertainParameters& p,
                                                                       double omega_rad_s,
                                                                       double angular_gain_k);

/// The drift rate theta' [rad/s] at (r, k, theta) with its CI: the chain rule over the averaged
/// equations of every term the values hold (orbit_rates_chain_rule.h; (5.9) for the paper's).
ParameterEstimate driftRateWithInterval(double r, double k, double theta,
                                        const UncertainParameters& p);

/// The mean of theta' over states of a record (e.g. a live window) with its CI: the delta method
/// over the parameters of the mean (the model's prediction averaged, not a measured drift).
/// InputError when no state is given.
ParameterEstimate meanDriftRateWithInterval(const std::vector<OrbitElements>& states,
                                            const UncertainParameters& p);

/// Q = omega / rate from a decay rate with its variance (e.g. the envelope rate c'z, variance
/// c' cov c): interval from the rate's Student-t interval mapped through omega / rate (asymmetric),
/// std by the delta method. InputError when the rate is not positive.
ParameterEstimate qualityFactorFromRate(double omega_rad_s, double rate, double rate_variance,
                                        double confidence, int dof);

/// The section-4 quantities of e with intervals, from its well-identified combinations: when gamma
/// is not identified (e.not_identified) and e.envelope_coefficients exist, "Q" is the envelope's
/// Q (and derived_method says so); "Q_envelope" is added whenever the envelope exists. Fills
/// e->derived, e->derived_method and notes; nothing when omega <= 0 or the rank is deficient.
void deriveFromIdentified(Estimate* e, double omega_rad_s, double angular_gain_k);

}  // namespace cvg_bench
