#include "cvg_bench/core/estimate/uncertainty/derived_uncertainty.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/derived_quantities.h"
#include "cvg_bench/core/estimate/uncertainty/student_t.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "cvg_bench/core/model/orbit_rates_chain_rule.h"

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

Eigen::VectorXd deltaMethodGradient(const std::function<double(const ParameterValues&)>& f,
                                    const UncertainParameters& p) {
  const int n = static_cast<int>(p.cov_names.size());
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
  return grad;
}

ParameterEstimate deltaMethod(const std::function<double(const ParameterValues&)>& f,
                              const UncertainParameters& p) {
  ParameterEstimate out;
  out.value = f(p.values);
  requireFinite(out.value, "derived value");
  if (p.cov_names.empty()) {
    out.ci_low = out.ci_high = out.value;
    return out;
  }
  const Eigen::VectorXd grad = deltaMethodGradient(f, p);
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
  // theta' by the chain rule over the averaged equations of the model the values hold (every
  // registered term; (5.9) for the paper's terms): orbit_rates_chain_rule.h.
  if (!std::isfinite(theta)) throw InputError("drift: theta must be finite");
  const ResonatorModel model = freeOscillationModelOf(p.values);
  const OrbitElements e{r, k, theta, 0.0};
  return deltaMethod(
      [&](const ParameterValues& v) { return orbitRatesOfModel(model, v, e).theta_dot; }, p);
}

ParameterEstimate meanDriftRateWithInterval(const std::vector<OrbitElements>& states,
                                            const UncertainParameters& p) {
  if (states.empty()) throw InputError("drift: no state to average over");
  const ResonatorModel model = freeOscillationModelOf(p.values);
  return deltaMethod(
      [&](const ParameterValues& v) {
        double sum = 0.0;
        for (const OrbitElements& e : states) sum += orbitRatesOfModel(model, v, e).theta_dot;
        return sum / static_cast<double>(states.size());
      },
      p);
}

ParameterEstimate qualityFactorFromRate(double omega_rad_s, double rate, double rate_variance,
                                        double confidence, int dof) {
  if (!(rate > 0.0) || !std::isfinite(rate))
    throw InputError("the decay rate " + std::to_string(rate) + " 1/s is not positive: no Q");
  ParameterEstimate q;
  const double sd = std::sqrt(std::max(0.0, rate_variance));
  const double s_p = studentQuantile(confidence, dof);
  q.value = omega_rad_s / rate;
  q.std_error = q.value * sd / rate;
  const double low_rate = rate - s_p * sd;
  q.ci_low = omega_rad_s / (rate + s_p * sd);
  q.ci_high = low_rate > 0.0 ? omega_rad_s / low_rate : std::numeric_limits<double>::infinity();
  return q;
}

namespace {

bool contains(const std::vector<std::string>& v, const std::string& x) {
  return std::find(v.begin(), v.end(), x) != v.end();
}

/// The parameters among `suspects` that move the derived quantity `key` (a step of 1e-3 (1 + |v|)
/// changes it by more than 1e-9 of its size).
std::vector<std::string> dependsOn(const ParameterValues& values, const std::string& key,
                                   const std::vector<std::string>& suspects, double omega_rad_s,
                                   double angular_gain_k) {
  std::vector<std::string> out;
  const double v0 = deriveQuantities(values, omega_rad_s, angular_gain_k).asMap().at(key);
  for (const auto& name : suspects) {
    const auto it = values.find(name);
    if (it == values.end()) continue;
    ParameterValues moved = values;
    moved[name] = it->second + 1e-3 * (1.0 + std::fabs(it->second));
    try {
      const double v1 = deriveQuantities(moved, omega_rad_s, angular_gain_k).asMap().at(key);
      if (!(std::fabs(v1 - v0) <= 1e-9 * (1.0 + std::fabs(v0)))) out.push_back(name);
    } catch (const InputError&) {
      out.push_back(name);
    }
  }
  return out;
}

/// Issue #25: a derived figure computed from a parameter the record does not identify (VIF >=
/// 1e4, collinearity.h) is no estimate; it is removed and a note names what it needs. Q is left
/// to the envelope rule below (Q_envelope stands in for omega/gamma).
void dropFiguresOfUnidentified(Estimate* e, double omega_rad_s, double angular_gain_k) {
  if (e->not_identified.empty()) return;
  ParameterValues values;
  for (size_t j = 0; j < e->names.size() && static_cast<Eigen::Index>(j) < e->values.size(); ++j)
    values[e->names[j]] = e->values[static_cast<Eigen::Index>(j)];
  for (auto it = e->derived.begin(); it != e->derived.end();) {
    const std::vector<std::string> needs =
        it->first == "Q"
            ? std::vector<std::string>{}
            : dependsOn(values, it->first, e->not_identified, omega_rad_s, angular_gain_k);
    if (needs.empty()) {
      ++it;
      continue;
    }
    std::string list;
    for (const auto& n : needs) list += (list.empty() ? "" : ", ") + n;
    const std::string note = it->first + " not reported: it depends on " + list +
                             ", which this record does not identify";
    if (!contains(e->notes, note)) e->notes.push_back(note);
    it = e->derived.erase(it);
  }
}

}  // namespace

void deriveFromIdentified(Estimate* e, double omega_rad_s, double angular_gain_k) {
  e->derived.clear();
  e->derived_method.clear();
  if (!(omega_rad_s > 0.0)) {
    e->notes.push_back("derived quantities not computed: omega unknown (give --omega)");
    return;
  }
  const int k = static_cast<int>(e->names.size());
  const bool full_rank = e->rank >= e->n_params;
  if (full_rank) {
    try {
      e->derived =
          deriveQuantitiesWithIntervals(uncertainParameters(*e), omega_rad_s, angular_gain_k);
    } catch (const InputError& err) {
      e->notes.push_back(std::string("derived quantities not computed: ") + err.what());
    }
    dropFiguresOfUnidentified(e, omega_rad_s, angular_gain_k);
  }
  const Eigen::VectorXd& c = e->envelope_coefficients;
  if (!full_rank || c.size() != k || e->values.size() != k || e->covariance.rows() != k) return;
  const std::string how =
      "from the envelope decay of this record: gamma_env = -sum q' D(q) z / sum |q|^2 dt "
      "(section 4's Q = omega/gamma with the record's own damping of |q|^2)";
  try {
    const ParameterEstimate q_env = qualityFactorFromRate(
        omega_rad_s, c.dot(e->values), c.dot(e->covariance * c), e->confidence, e->interval_dof);
    e->derived["Q_envelope"] = q_env;
    e->derived_method["Q_envelope"] = how;
    const bool gamma_unknown =
        contains(e->not_identified, "gamma") || contains(e->unidentifiable, "gamma");
    // omega/gamma whose interval reaches 0 or below: the record does not bound gamma away from
    // 0 (e.g. gamma_nl takes the damping), so it is no Q (issue #25: nothing not determined is
    // printed as a number).
    const auto q_gamma = e->derived.find("Q");
    const bool gamma_unbounded = q_gamma != e->derived.end() &&
                                 !(q_gamma->second.value > 0.0 && q_gamma->second.ci_low > 0.0);
    if (gamma_unknown || gamma_unbounded) {
      const std::string why =
          gamma_unknown
              ? "the split of the damping between gamma and the anisotropy b is not identified "
                "by this record, so omega/gamma is not reported"
              : "omega/gamma is not reported: its interval reaches 0 or below (gamma not bounded "
                "away from 0 by this record)";
      e->derived["Q"] = q_env;
      e->derived_method["Q"] = "Q " + how + "; " + why;
    } else if (e->derived.count("Q")) {
      e->derived_method["Q"] = "omega/gamma";
    }
  } catch (const InputError& err) {
    e->notes.push_back(std::string("Q from the envelope not computed: ") + err.what());
  }
}

}  // namespace cvg_bench
