#include "cvg_bench/core/estimate/derived_uncertainty.h"

#include <cmath>

#include "cvg_bench/core/estimate/derived_quantities.h"
#include "cvg_bench/core/estimate/student_t.h"
#include "cvg_bench/core/model/errors.h"
#include "cvg_bench/core/model/orbit_elements.h"

namespace cvg_bench {

UncertainParameters uncertainParameters(const Estimate& e) {
  UncertainParameters p;
  for (size_t j = 0; j < e.names.size() && static_cast<Eigen::Index>(j) < e.values.size(); ++j)
    p.values[e.names[j]] = e.values[static_cast<Eigen::Index>(j)];
  if (e.covariance.rows() == static_cast<Eigen::Index>(e.names.size())) {
    p.cov_names = e.names;
    p.covariance = e.covariance;
  }
  p.dof = e.interval_dof;
  p.confidence = e.confidence;
  return p;
}

ParameterEstimate deltaMethod(const std::function<double(const ParameterValues&)>& f,
                              const UncertainParameters& p) {
  ParameterEstimate out;
  out.value = f(p.values);
  requireFinite(out.value, "derived value");
  const int n = static_cast<int>(p.cov_names.size());
  if (n == 0) {
    out.ci_low = out.ci_high = out.value;
    return out;
  }
  if (p.covariance.rows() != n || p.covariance.cols() != n)
    throw InputError("covariance is not " + std::to_string(n) + " x " + std::to_string(n));
  Eigen::VectorXd grad(n);
  for (int j = 0; j < n; ++j) {
    const auto it = p.values.find(p.cov_names[j]);
    const double v = it == p.values.end() ? 0.0 : it->second;
    const double sd = std::sqrt(std::max(0.0, p.covariance(j, j)));
    // A small fraction of the standard error: the delta method's own linearization scale.
    const double h = sd > 0.0 ? 1e-4 * sd : 1e-7 * std::max(1.0, std::fabs(v));
    ParameterValues plus = p.values, minus = p.values;
    plus[p.cov_names[j]] = v + h;
    minus[p.cov_names[j]] = v - h;
    grad[j] = (f(plus) - f(minus)) / (2.0 * h);
  }
  return interval(out.value, grad.dot(p.covariance * grad), studentQuantile(p.confidence, p.dof));
}

std::map<std::string, ParameterEstimate> deriveQuantitiesWithIntervals(const UncertainParameters& p,
                                                                       double omega_rad_s,
                                                                       double angular_gain_k) {
  std::map<std::string, ParameterEstimate> out;
  for (const auto& kv : deriveQuantities(p.values, omega_rad_s, angular_gain_k).asMap()) {
    const std::string key = kv.first;
    out[key] = deltaMethod(
        [&](const ParameterValues& v) {
          return deriveQuantities(v, omega_rad_s, angular_gain_k).asMap().at(key);
        },
        p);
  }
  return out;
}

ParameterEstimate driftRateWithInterval(double r, double k, double theta,
                                        const UncertainParameters& p) {
  return deltaMethod([&](const ParameterValues& v) { return driftRate(r, k, theta, v); }, p);
}

}  // namespace cvg_bench
