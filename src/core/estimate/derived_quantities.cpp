#include "cvg_bench/core/estimate/derived_quantities.h"

#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/model/orbit_elements.h"

namespace cvg_bench {

std::map<std::string, double> DerivedQuantities::asMap() const {
  return {{"Q", Q},
          {"zero_rate_rad_s", zero_rate_rad_s},
          {"frequency_error_rad_s", frequency_error_rad_s},
          {"frequency_error_hz", frequency_error_hz},
          {"frequency_split_rad_s", frequency_split_rad_s},
          {"frequency_split_hz", frequency_split_hz},
          {"damping_anisotropy_1_s", damping_anisotropy_1_s},
          {"alpha_rad", alpha_rad},
          {"beta_rad", beta_rad}};
}

DerivedQuantities deriveQuantities(const ParameterValues& z, double omega_rad_s,
                                   double angular_gain_k) {
  requirePositive(omega_rad_s, "omega");
  requirePositive(angular_gain_k, "angular gain K");
  for (const auto& kv : z) requireFinite(kv.second, "parameter " + kv.first);
  auto get = [&](const char* n) {
    auto it = z.find(n);
    return it == z.end() ? 0.0 : it->second;
  };
  const double gamma = get("gamma");
  if (gamma == 0.0) throw InputError("gamma is 0: the quality factor Q = omega/gamma is undefined");
  const DefectAxes ax = defectAxes(z);
  DerivedQuantities d;
  d.Q = omega_rad_s / gamma;
  d.zero_rate_rad_s = get("nu") / (4.0 * angular_gain_k);
  d.frequency_error_rad_s = get("c_m") / 2.0;
  d.frequency_error_hz = d.frequency_error_rad_s / (2.0 * M_PI);
  d.frequency_split_rad_s = ax.h_m;
  d.frequency_split_hz = ax.h_m / (2.0 * M_PI);
  d.damping_anisotropy_1_s = 2.0 * ax.b_m;
  d.alpha_rad = ax.alpha;
  d.beta_rad = ax.beta;
  return d;
}

}  // namespace cvg_bench
