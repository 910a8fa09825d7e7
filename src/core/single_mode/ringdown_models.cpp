#include "cvg_bench/core/single_mode/ringdown_models.h"

#include <boost/math/special_functions/expint.hpp>
#include <cmath>
#include <limits>

#include "cvg_bench/core/model/errors.h"

namespace cvg_bench {
namespace {

/// (1 - e^{-k t}) / k, stable as k -> 0 (limit t).
double oneMinusExpOver(double k, double t) {
  if (std::fabs(k * t) < 1e-10) return t;
  return -std::expm1(-k * t) / k;
}

}  // namespace

std::vector<std::string> ringdownParameterNames(const std::string& model) {
  if (model == "linear") return {"a", "g"};
  if (model == "gamma_nl") return {"a", "g0", "g2"};
  if (model == "gamma_a") return {"a", "g0", "g1"};
  if (model == "beat") return {"a1", "d1", "a2", "d2", "w", "phi"};
  if (model == "two_stage") return {"a1", "d1", "a2", "d2"};
  throw InputError("ring-down model '" + model +
                   "' unknown: use linear, gamma_nl, gamma_a, beat or two_stage");
}

const std::vector<std::string>& ringdownExtensionNames() {
  static const std::vector<std::string> names = {"gamma_nl", "gamma_a", "beat", "two_stage"};
  return names;
}

double ringdownLogAmplitude(const std::string& model, const Eigen::VectorXd& p, double t,
                            double floor_rel) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  double log_a = nan;
  if (model == "linear") {
    log_a = p(0) - p(1) * t;
  } else if (model == "gamma_nl") {
    const double den = 1.0 + 2.0 * p(2) * std::exp(2.0 * p(0)) * oneMinusExpOver(2.0 * p(1), t);
    if (!(den > 0.0)) return nan;
    log_a = p(0) - p(1) * t - 0.5 * std::log(den);
  } else if (model == "gamma_a") {
    const double den = 1.0 + p(2) * std::exp(p(0)) * oneMinusExpOver(p(1), t);
    if (!(den > 0.0)) return nan;
    log_a = p(0) - p(1) * t - std::log(den);
  } else if (model == "beat") {
    const double l1 = p(0) - p(1) * t, l2 = p(2) - p(3) * t;
    const double m = std::max(l1, l2);
    const double e1 = std::exp(l1 - m), e2 = std::exp(l2 - m);
    const double pw = e1 * e1 + e2 * e2 + 2.0 * e1 * e2 * std::cos(p(4) * t + p(5));
    if (!(pw > 0.0)) return nan;
    log_a = m + 0.5 * std::log(pw);
  } else if (model == "two_stage") {
    const double l1 = p(0) - p(1) * t, l2 = p(2) - p(3) * t;
    const double m = std::max(l1, l2);
    log_a = m + 0.5 * std::log(std::exp(2.0 * (l1 - m)) + std::exp(2.0 * (l2 - m)));
  } else {
    ringdownParameterNames(model);  // throws
  }
  if (!(floor_rel > 0.0)) return log_a;
  // Mean of ln|A + n| for circular Gaussian n of rms F (a Rice magnitude): ln A + E1(A^2/F^2) / 2
  // (exact; below ~0.1 A^2/F^2 the floor dominates and the mean tends to ln F - 0.289).
  const double x = std::exp(2.0 * log_a) / (floor_rel * floor_rel);
  if (x > 40.0) return log_a;
  if (x < 1e-8) return std::log(floor_rel) - 0.5 * 0.5772156649015329;
  return log_a + 0.5 * boost::math::expint(1, x);
}

}  // namespace cvg_bench
