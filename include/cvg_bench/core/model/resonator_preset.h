// Resonator presets for the simulator: true parameters, drive, noise and experiment settings,
// loaded from YAML (config/resonators/*.yaml, every key documented there with its unit).
// Shipped: mems_ring (the paper's section-4 MEMS ring), hrg_hemispherical, quartz_cylinder.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

struct ResonatorPreset {
  /// Preset name (file stem for shipped presets).
  std::string name;
  /// One line: what resonator this is.
  std::string description;
  /// Natural frequency omega [rad/s], > 0.
  double omega_rad_s = 0.0;
  /// True model parameters in regression units (resonator_model.h): gamma, nu, b_c, b_s, c_m, n,
  /// h_c, h_s and the extensions xi, kappa, gamma_nl, cm_rate, xi_diff (0 or absent = off).
  ParameterValues parameters;

  /// Drive u~1..u~4 of (3.1) [1/s x amplitude, tilde = eta u_i / omega].
  Eigen::Vector4d drive_u_tilde = Eigen::Vector4d::Zero();
  /// Known control nonlinearity mu of (3.1) [1/amplitude^2]; 0 for magnetoelectric actuators.
  double mu = 0.0;
  /// Electrostatic coefficient eta of (2.1) [1/s^2, normalized amplitudes] for the 2 omega0
  /// parametric terms (docs/paper.md item 6), simulator only; 0 = off (as in (3.1)).
  double eta = 0.0;

  /// Measurement noise std on q1, p1, q2, p2 of slow and sweep records [amplitude units], >= 0.
  double noise_q_std = 0.0;
  /// Measurement noise std on raw f, g [amplitude units], >= 0.
  double noise_fg_std = 0.0;
  /// RK4 steps per period of the full equations, >= 4.
  int steps_per_period = 20;

  /// Free decay: record length of the slow record [s], > 0.
  double decay_duration_s = 0.0;
  /// Free decay: sample rate of the slow record [Hz], > 0.
  double decay_sample_rate_hz = 0.0;
  /// Free decay: record length of the raw record (--raw) [s], > 0.
  double decay_raw_duration_s = 0.0;
  /// Free decay: detuning omega0 - omega of the stationary forced oscillation the decay starts
  /// from [rad/s]; the controls are switched off at t = 0.
  double decay_drive_detuning_rad_s = 0.0;
  /// Sample rate of raw records [Hz], above the Nyquist rate omega / pi.
  double raw_sample_rate_hz = 0.0;

  /// Forced sweep: first and last detuning lambda = omega0 - omega [rad/s], min < max.
  double sweep_lambda_min_rad_s = 0.0;
  double sweep_lambda_max_rad_s = 0.0;
  /// Forced sweep: number of detunings (equally spaced), >= 2.
  int sweep_points = 0;
  /// Forced sweep: longest settling time per step [s], > 0 (a step ends earlier once stationary).
  double sweep_settle_time_s = 0.0;
  /// Forced sweep: stationary when |q'| < tolerance * gamma * max(|q|, 1e-6) (relative), > 0.
  double sweep_settle_tolerance = 1e-9;
  /// Forced sweep: also sweep back down (hysteresis of a bistable resonator).
  bool sweep_down = false;
  /// Forced sweep with --raw: length of the raw record of each settled step [s], > 0.
  double sweep_raw_duration_s = 0.0;
  /// Forced sweep with --raw: full-equation settling before each raw segment (discarded) [s], >= 0.
  double sweep_raw_settle_s = 0.0;

  /// Every problem at once (empty when valid).
  std::vector<std::string> validate() const;
  /// Applies `--effect NAME=VALUE`: NAME is a model parameter (gamma ... h_s, xi, kappa, gamma_nl,
  /// cm_rate, xi_diff), u1..u4, mu or eta. InputError for an unknown name or a non-finite value.
  void applyEffect(const std::string& name, double value);
  /// Applies "NAME=VALUE".
  void applyEffect(const std::string& assignment);
  /// The truth model for a mode: `linear` plus every extension with a nonzero parameter.
  /// InputError when a nonzero parameter's term does not exist in that mode (cm_rate forced).
  /// With skip_inapplicable, terms that do not exist in `mode` are left out instead of refused
  /// (the forced pre-drive before a free decay ignores effects such as cm_rate that start at t =
  /// 0).
  std::string truthModelSpec(ExperimentMode mode, bool skip_inapplicable = false) const;
  /// z of the truth model (drive u~ included in forced mode).
  Eigen::VectorXd truthParameters(const ResonatorModel& model) const;
};

/// Names --effect accepts: the model parameters (from the model terms), u1..u4, mu, eta.
std::vector<std::string> effectNames();

/// Loads a preset file; InputError listing every problem (YAML syntax with line:column, unknown
/// keys, wrong types, failed validate()).
ResonatorPreset loadResonatorPresetFile(const std::string& path);
/// A shipped preset by name, from presetDirectory().
ResonatorPreset loadShippedPreset(const std::string& name);
/// Where shipped presets live: $CVG_BENCH_PRESET_DIR, else config/resonators of the installed or
/// source package (package_resources.h), else ./config/resonators.
std::string presetDirectory();
/// Names (file stems) of the presets in presetDirectory(), sorted.
std::vector<std::string> shippedPresetNames();

}  // namespace cvg_bench
