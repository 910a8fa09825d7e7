#include "cvg_bench/core/diagnose/quadrature_growth.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <sstream>

#include "cvg_bench/core/common/number_text.h"
#include "cvg_bench/core/model/orbit_rates_chain_rule.h"

namespace cvg_bench {
namespace {

/// The parameters of one term with one meaning (ModelTerm::parameterMeaning).
struct ParameterGroup {
  std::vector<std::string> parameters;
  std::string meaning;
};

std::vector<ParameterGroup> groupsOf(const ResonatorModel& model) {
  std::vector<ParameterGroup> groups;
  for (const ModelTermPtr& term : model.terms()) {
    const size_t first = groups.size();
    for (const std::string& p : term->parameterNames()) {
      const std::string meaning = term->parameterMeaning(p);
      auto same = std::find_if(groups.begin() + first, groups.end(),
                               [&](const ParameterGroup& g) { return g.meaning == meaning; });
      if (same == groups.end())
        groups.push_back({{p}, meaning});
      else
        same->parameters.push_back(p);
    }
  }
  return groups;
}

/// Union-find root with path halving.
size_t rootOf(std::vector<size_t>& parent, size_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

/// Merges the groups whose shares' delta-method correlation exceeds `limit` in magnitude.
std::vector<ParameterGroup> mergeInseparable(
    const std::vector<ParameterGroup>& groups,
    const std::vector<std::function<double(const ParameterValues&)>>& shares,
    const UncertainParameters& params, double limit) {
  std::vector<Eigen::VectorXd> grads;
  for (const auto& f : shares) grads.push_back(deltaMethodGradient(f, params));
  std::vector<size_t> parent(groups.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (size_t i = 0; i < groups.size(); ++i)
    for (size_t j = i + 1; j < groups.size(); ++j) {
      const double vi = grads[i].dot(params.covariance * grads[i]);
      const double vj = grads[j].dot(params.covariance * grads[j]);
      if (!(vi > 0.0) || !(vj > 0.0)) continue;
      const double corr = grads[i].dot(params.covariance * grads[j]) / std::sqrt(vi * vj);
      if (std::abs(corr) > limit) parent[rootOf(parent, j)] = rootOf(parent, i);
    }
  std::vector<ParameterGroup> merged;
  std::vector<size_t> slot(groups.size(), groups.size());
  for (size_t i = 0; i < groups.size(); ++i) {
    const size_t root = rootOf(parent, i);
    if (slot[root] == groups.size()) {
      slot[root] = merged.size();
      merged.push_back(groups[i]);
      continue;
    }
    ParameterGroup& m = merged[slot[root]];
    m.parameters.insert(m.parameters.end(), groups[i].parameters.begin(),
                        groups[i].parameters.end());
    m.meaning += " + " + groups[i].meaning;
  }
  return merged;
}

std::string withInterval(const ParameterEstimate& e) {
  return valueWithInterval(e.value, e.ci_low, e.ci_high, 3);
}

std::string summaryOf(const QuadratureGrowth& g, const std::string& model) {
  std::ostringstream s;
  s.precision(4);
  s << "the ellipse's width |k| changes at " << withInterval(g.measured_widening)
    << " amplitude/s measured; " << model << " gives " << withInterval(g.predicted_widening)
    << " at r " << g.r << ", k " << g.k << ", of which";
  for (size_t i = 0; i < g.shares.size(); ++i)
    s << (i ? "; " : " ") << g.shares[i].meaning << " " << withInterval(g.shares[i].widening)
      << (g.shares[i].determined ? "" : " (not determined)");
  if (g.named.empty())
    s << ". No group carries the widening on its own: the record does not say what makes it";
  else {
    s << ". Named cause of the " << (g.predicted_widening.value > 0 ? "widening" : "narrowing")
      << ": " << g.named.front();
    for (size_t i = 1; i < g.named.size(); ++i) s << ", then " << g.named[i];
  }
  const bool same_sign = g.measured_widening.value * g.predicted_widening.value > 0.0;
  if (!same_sign) s << " (the model's sign differs from the measured one)";
  return s.str();
}

}  // namespace

QuadratureGrowth explainQuadratureGrowth(const UncertainParameters& params, double r, double k,
                                         double theta_rad, const ParameterEstimate& measured_k_rate,
                                         const QuadratureGrowthOptions& options) {
  QuadratureGrowth out;
  out.r = r;
  out.k = k;
  out.theta_rad = theta_rad;
  if (params.cov_names.empty()) {
    out.why_not = "the estimate has no covariance";
    return out;
  }
  if (!(r > 0.0) || !(std::abs(r * r - k * k) > 1e-12 * r * r)) {
    out.why_not = "no standing wave at the state (r = |k|)";
    return out;
  }
  // d|k|/dt = sign(k) k' (at k = 0 the widening is k' itself).
  const double sign = k < 0.0 ? -1.0 : 1.0;
  out.measured_widening = measured_k_rate;
  if (sign < 0) {
    out.measured_widening.value = -measured_k_rate.value;
    out.measured_widening.ci_low = -measured_k_rate.ci_high;
    out.measured_widening.ci_high = -measured_k_rate.ci_low;
  }
  const ResonatorModel model = freeOscillationModelOf(params.values);
  const OrbitElements state{r, k, theta_rad, 0.0};
  auto widening = [&](const ParameterValues& v) {
    return sign * orbitRatesOfModel(model, v, state).k_dot;
  };
  out.predicted_widening = deltaMethod(widening, params);
  auto shareOf = [&](const std::vector<std::string>& names) {
    return [&, names](const ParameterValues& v) {
      ParameterValues without = v;
      for (const std::string& p : names) without[p] = 0.0;
      return widening(v) - widening(without);
    };
  };
  const std::vector<ParameterGroup> groups = groupsOf(model);
  std::vector<std::function<double(const ParameterValues&)>> fs;
  for (const ParameterGroup& g : groups) fs.push_back(shareOf(g.parameters));
  for (const ParameterGroup& g : mergeInseparable(groups, fs, params, options.merge_correlation)) {
    QuadratureShare s;
    s.parameters = g.parameters;
    s.meaning = g.meaning;
    s.widening = deltaMethod(shareOf(g.parameters), params);
    s.determined = s.widening.ci_low > 0.0 || s.widening.ci_high < 0.0;
    // A group that does not enter k' (nu, c_m: theta' and chi' only) is not a share: its value
    // and error are rounding of the chain rule's differences, under 1e-6 of the model's.
    const double scale = std::abs(out.predicted_widening.value) + out.predicted_widening.std_error;
    if (std::abs(s.widening.value) + s.widening.std_error <= 1e-6 * scale) continue;
    out.shares.push_back(s);
  }
  std::sort(out.shares.begin(), out.shares.end(),
            [](const QuadratureShare& a, const QuadratureShare& b) {
              return std::abs(a.widening.value) > std::abs(b.widening.value);
            });
  for (const QuadratureShare& s : out.shares)
    if (s.determined && s.widening.value * out.predicted_widening.value > 0.0)
      out.named.push_back(s.meaning);
  out.valid = true;
  out.summary = summaryOf(out, model.spec());
  return out;
}

}  // namespace cvg_bench
