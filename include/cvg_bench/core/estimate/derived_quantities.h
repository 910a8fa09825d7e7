// Derived quantities of section 4 from an estimate z (regression units, see resonator_model.h).
#pragma once

#include <map>
#include <string>

#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

struct DerivedQuantities {
  double Q = 0.0;                       ///< quality factor omega / gamma
  double zero_rate_rad_s = 0.0;         ///< zero-rate signal Omega = nu / (4 K) [rad/s]
  double frequency_error_rad_s = 0.0;   ///< c~m / 2 [rad/s]
  double frequency_error_hz = 0.0;      ///< c~m / (4 pi) [Hz]
  double frequency_split_rad_s = 0.0;   ///< sqrt(h~c^2 + h~s^2) [rad/s]
  double frequency_split_hz = 0.0;      ///< the same / (2 pi) [Hz]
  double damping_anisotropy_1_s = 0.0;  ///< gamma_max - gamma_min = 2 sqrt(b_c^2 + b_s^2) [1/s]
  double alpha_rad = 0.0;               ///< stiffness axis angle atan2(h~s, h~c) / 4 [rad]
  double beta_rad = 0.0;                ///< damping axis angle atan2(b_s, b_c) / 4 [rad]

  /// The JSON field names of interfaces.md mapped to the values.
  std::map<std::string, double> asMap() const;
};

/// Section 4's quantities. omega_rad_s > 0, angular_gain_k > 0 (0.4 for a ring) and a finite,
/// nonzero gamma are required (InputError otherwise).
DerivedQuantities deriveQuantities(const ParameterValues& z, double omega_rad_s,
                                   double angular_gain_k);

}  // namespace cvg_bench
