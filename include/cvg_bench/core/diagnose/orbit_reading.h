// What a free-decay record shows before any model (issue #25 "measure before modelling"): the
// orbit elements r, k, theta of every slow sample by (5.2) and, in equal windows of time, the
// pattern angle's rate, the quadrature's and the amplitude's course and the Q the amplitude decay
// implies; each window's measured theta' beside the selected model's prediction there (chain rule,
// orbit_rates_chain_rule.h). Rates are least-squares slopes with HAC (Newey-West) standard errors
// inside a window; the record's mean rate is the mean of the window rates with a Student-t interval
// from their scatter (B - 1 dof: honest when residuals are correlated within a window, and wide
// when the rate itself changes).
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/diagnose/quadrature_growth.h"
#include "cvg_bench/core/estimate/estimate.h"
#include "cvg_bench/core/io/records.h"

namespace cvg_bench {

struct OrbitWindow {
  double t_start_s = 0.0, t_end_s = 0.0;
  int n = 0;
  double r = 0.0, k = 0.0, theta_rad = 0.0;  ///< medians in the window
  ParameterEstimate theta_rate;              ///< measured theta' [rad/s]
  ParameterEstimate k_rate;                  ///< measured k' [amplitude/s]
  ParameterEstimate q;                       ///< omega / (-2 r'/r); value 0 when r does not fall
  bool has_prediction = false;
  ParameterEstimate predicted_theta_rate;  ///< the model's theta' at (r, k, theta) [rad/s]
  ParameterEstimate predicted_k_rate;      ///< the model's k' there [amplitude/s]
};

struct OrbitReading {
  bool valid = false;
  std::string why_not;  ///< when not valid
  double period_s = 0.0;
  int n_samples = 0;
  std::vector<OrbitWindow> windows;
  ParameterEstimate theta_rate;  ///< over the record (mean of the windows) [rad/s]
  ParameterEstimate k_rate;      ///< over the record [amplitude/s]
  std::string model;             ///< the model of the predictions ("" without one)
  /// The windows' theta' against r k / 8 (the form of (5.9)'s cubic coupling; where the pattern
  /// angle hardly moves, the anisotropy's k / r term rides along, as r changes little): the slope
  /// the record shows [1/(s amplitude^2)], its error from the windows' scatter about the line
  /// (Student-t, windows - 2 dof), and the same slope of the model's predictions at the windows'
  /// states. Zero under 4 windows.
  ParameterEstimate rk_slope_measured, rk_slope_model;
  /// With a model: what makes the ellipse's width change, at the record's median state against
  /// the measured k_rate (quadrature_growth.h); invalid without a model or its covariance.
  QuadratureGrowth quadrature_growth;
  std::string summary;  ///< one paragraph for the text report
};

/// Reads the orbit of a free-decay slow record (omega from the record or `omega_rad_s`); with a
/// final estimate (may be null) every window gets the model's theta' prediction with its interval.
OrbitReading readOrbit(const SlowRecord& record, double omega_rad_s, const Estimate* final_estimate,
                       int n_windows = 8, double confidence = 0.95);

}  // namespace cvg_bench
