// Physical sanity checks of an estimate (see estimate_sanity.h).
#include "cvg_bench/ros/estimate_sanity.h"

#include <cmath>
#include <sstream>

namespace cvg_bench {
namespace {

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(4);
  s << v;
  return s.str();
}

const ParameterEstimate* find(const std::map<std::string, ParameterEstimate>& m,
                              const std::string& name) {
  const auto it = m.find(name);
  return it == m.end() ? nullptr : &it->second;
}

}  // namespace

std::vector<std::string> sanityProblems(const Estimate& e) {
  std::vector<std::string> p;
  for (Eigen::Index i = 0; i < e.values.size(); ++i)
    if (!std::isfinite(e.values[i]))
      p.push_back("parameter " +
                  (i < static_cast<Eigen::Index>(e.names.size()) ? e.names[i] : "?") +
                  " is not finite");
  if (const ParameterEstimate* g = find(e.parameters, "gamma")) {
    if (!(g->value > 0.0))
      p.push_back("damping gamma = " + fmt(g->value) +
                  " 1/s is not positive (a growing oscillation: mixed runs or a wrong model?)");
    else if (g->ci_low <= 0.0)
      p.push_back("gamma interval [" + fmt(g->ci_low) + ", " + fmt(g->ci_high) +
                  "] 1/s reaches below 0: wider than physical");
    const ParameterEstimate* bc = find(e.parameters, "b_c");
    const ParameterEstimate* bs = find(e.parameters, "b_s");
    if (g->value > 0.0 && bc && bs) {
      const double half_split = std::hypot(bc->value, bs->value);
      if (half_split >= g->value)
        p.push_back("principal damping gamma - sqrt(b_c^2 + b_s^2) = " +
                    fmt(g->value - half_split) + " 1/s is not positive");
    }
  }
  if (const ParameterEstimate* q = find(e.derived, "Q")) {
    if (!(q->value > 0.0))
      p.push_back("quality factor Q = " + fmt(q->value) + " is not positive");
    else if (q->ci_low <= 0.0)
      p.push_back("Q interval [" + fmt(q->ci_low) + ", " + fmt(q->ci_high) +
                  "] reaches below 0: wider than physical");
  }
  for (const char* angle : {"alpha_rad", "beta_rad"})
    if (const ParameterEstimate* a = find(e.derived, angle))
      if (a->ci_high - a->ci_low >= M_PI / 2)
        p.push_back(std::string(angle) + " interval is " + fmt(a->ci_high - a->ci_low) +
                    " rad wide, the whole period pi/2: that axis is not determined");
  return p;
}

}  // namespace cvg_bench
