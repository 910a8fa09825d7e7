// One mode's stationary response with branch following (response_model.h).
#include "cvg_bench/core/single_mode/response_model.h"

#include <algorithm>
#include <boost/math/tools/roots.hpp>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/single_mode/response_laws.h"

namespace cvg_bench {
namespace {

/// h(u) = u |D(u)|^2 = A u^3 + B u^2 + C u for one drive frequency.
struct Cubic {
  double A, B, C;
  double operator()(double u) const { return ((A * u + B) * u + C) * u; }
  double slope(double u) const { return (3.0 * A * u + 2.0 * B) * u + C; }
};

Cubic cubicAt(const ResponseParams& p, double f) {
  const double a = p.f0_hz * p.f0_hz - f * f;
  const double b = 2.0 * p.f0_hz * p.backbone_hz_per_amp2;
  const double c = f * p.width_hz;
  const double d = f * p.width_growth_hz_per_amp2;
  return {b * b + d * d, 2.0 * (a * b + c * d), a * a + c * c};
}

/// The root of h(u) = power in [lo, hi] where h - power changes sign (h monotonic there).
double rootIn(const Cubic& h, double power, double lo, double hi) {
  std::uintmax_t iters = 60;
  const auto r =
      boost::math::tools::toms748_solve([&](double u) { return h(u) - power; }, lo, hi,
                                        boost::math::tools::eps_tolerance<double>(44), iters);
  return 0.5 * (r.first + r.second);
}

std::complex<double> shapeOf(const ResponseParams& p, ResponseKind kind, double f) {
  return kind == ResponseKind::kVelocity ? std::complex<double>(f / p.f0_hz, 0.0) : 1.0;
}

}  // namespace

std::string ResponseTerms::name() const {
  std::string s;
  for (const ResponseLaw& law : responseLaws())
    if (this->*law.flag) s += (s.empty() ? "" : "+") + std::string(law.name);
  return s.empty() ? kLinearResponseModel : s;
}

ResponseTerms parseResponseTerms(const std::string& model) {
  ResponseTerms t;
  if (model == kLinearResponseModel) return t;
  std::stringstream ss(model);
  std::string item;
  while (std::getline(ss, item, '+')) {
    const ResponseLaw* law = findResponseLaw(item);
    if (!law) {
      std::string known;
      for (const ResponseTerms& c : responseTermCombinations())
        known += (known.empty() ? "" : ", ") + c.name();
      throw InputError("--model: '" + item + "' is not a one-mode term (--mode response: " + known +
                       "; two-mode terms such as xi_diff or mu need two modes)");
    }
    t.*law->flag = true;
  }
  return t;
}

std::vector<double> stableSquaredAmplitudes(const ResponseParams& p, double f, double power) {
  const Cubic h = cubicAt(p, f);
  if (!(power > 0.0)) return {0.0};
  const double tiny = 1e-300;
  if (h.A <= tiny && std::abs(h.B) <= tiny) return {h.C > 0 ? power / h.C : 0.0};
  // Critical points of h (h' = 3A u^2 + 2B u + C); between them h falls (the unstable root).
  double u1 = -1.0, u2 = -1.0;
  const double disc = h.B * h.B - 3.0 * h.A * h.C;
  if (h.A > tiny && disc > 0.0) {
    const double s = std::sqrt(disc);
    const double q = -(h.B + std::copysign(s, h.B));
    const double ra = q / (3.0 * h.A), rb = q != 0.0 ? h.C / q : ra;
    u1 = std::min(ra, rb);
    u2 = std::max(ra, rb);
  }
  // Upper bracket: h(hi) > power.
  double hi = std::max(
      {u2, 0.0, std::cbrt(power / std::max(h.A, tiny)), h.C > 0 ? power / h.C : 0.0, 1e-300});
  for (int k = 0; k < 400 && h(hi) <= power; ++k) hi *= 2.0;
  std::vector<double> roots;
  if (u2 <= 0.0) {  // h rises on u >= 0
    roots.push_back(rootIn(h, power, 0.0, hi));
    return roots;
  }
  const double a0 = std::max(u1, 0.0);
  if (u1 > 0.0 && h(a0) >= power) roots.push_back(rootIn(h, power, 0.0, a0));
  if (h(u2) <= power) roots.push_back(rootIn(h, power, u2, hi));
  if (roots.empty()) roots.push_back(rootIn(h, power, 0.0, hi));  // numerically at a fold
  return roots;
}

std::vector<std::complex<double>> stationaryResponse(const ResponseParams& p,
                                                     const ResponseData& data,
                                                     std::vector<double>* u_out, int* jumps,
                                                     BranchChoice choice) {
  const size_t n = data.size();
  std::vector<std::complex<double>> out(n);
  if (u_out) u_out->assign(n, 0.0);
  if (jumps) *jumps = 0;
  const bool linear = p.backbone_hz_per_amp2 == 0.0 && p.width_growth_hz_per_amp2 == 0.0;
  double u_prev = 0.0;
  double other_prev = std::numeric_limits<double>::quiet_NaN();  // the other stable root, if any
  for (size_t i = 0; i < n; ++i) {
    const double f = data.frequency_hz[i];
    const double factor = data.resonant_drive_factor.empty() ? 1.0 : data.resonant_drive_factor[i];
    const std::complex<double> force = factor * data.drive[i] * p.gain;
    double u = 0.0;
    double other = std::numeric_limits<double>::quiet_NaN();
    if (!linear) {
      const std::vector<double> roots = stableSquaredAmplitudes(p, f, std::norm(force));
      u = roots.front();
      if (roots.size() == 2) {
        const double ref =
            choice == BranchChoice::kFollow
                ? u_prev
                : std::norm(data.z[i] - data.drive[i] * (p.bg0 + p.bg1 * (f - p.f_ref_hz)));
        const bool upper = std::abs(std::sqrt(roots[1]) - std::sqrt(ref)) <
                           std::abs(std::sqrt(roots[0]) - std::sqrt(ref));
        u = roots[upper ? 1 : 0];
        other = roots[upper ? 0 : 1];
      } else if (jumps && std::isfinite(other_prev) &&
                 std::abs(std::sqrt(u) - std::sqrt(other_prev)) <
                     std::abs(std::sqrt(u) - std::sqrt(u_prev))) {
        ++*jumps;  // the branch ended: the response went over to the other one
      }
    }
    const std::complex<double> D(
        p.f0_hz * p.f0_hz - f * f + 2.0 * p.f0_hz * p.backbone_hz_per_amp2 * u,
        f * (p.width_hz + p.width_growth_hz_per_amp2 * u));
    if (linear) u = std::norm(force / D);
    const std::complex<double> resonant = force * shapeOf(p, data.kind, f) / D;
    out[i] = data.drive[i] * (p.bg0 + p.bg1 * (f - p.f_ref_hz)) + resonant;
    if (u_out) (*u_out)[i] = u;
    u_prev = u;
    other_prev = other;
  }
  return out;
}

}  // namespace cvg_bench
