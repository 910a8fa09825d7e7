// A generator of one-mode lock-in sweeps that shares nothing with the fit (docs/response.md): the
// oscillator x'' + 2 pi (w0 + c2 x^2) x' + (2 pi f0)^2 x + k3 x^3 = F cos(phi) is integrated in
// time (RK4, 64 steps a cycle) through up and down sweeps at several drive levels, the state
// carried from point to point (so jumps and hysteresis happen by themselves), and demodulated like
// a lock-in over whole drive cycles at the end of each point's dwell.
#pragma once

#include <complex>

#include "cvg_bench/core/io/response_record.h"

namespace cvg_bench {

struct ResponseSimulatorOptions {
  double f0_hz = 200.0;
  double q = 200.0;
  int levels = 4;                         ///< drive levels, geometric from max/8 to max
  double max_amplitude = 1.0;             ///< linear peak amplitude at the top level (output units)
  double backbone_hz_per_amp2 = 0.0;      ///< xi in output units (k3 = xi 8/3 (2 pi)^2 f0)
  double width_growth_hz_per_amp2 = 0.0;  ///< g in output units (c2 = 4 g)
  double noise = 0.003;                   ///< sd of x and of y per point (output units)
  double correlation = 0.0;               ///< AR(1) coefficient of the noise along the record
  double f0_drift_hz = 0.0;               ///< sd of a per-sweep offset of f0 [Hz]
  std::complex<double> background{0.0, 0.0};  ///< at the top drive level (output units)
  std::complex<double> background_slope_per_hz{0.0, 0.0};
  ResponseKind kind = ResponseKind::kDisplacement;
  bool conjugate = false;             ///< write y with the other sign (lock-in convention)
  double saturation_amplitude = 0.0;  ///< > 0: the force saturates (F_sat tanh(F / F_sat))
  int sweeps_per_level = 2;           ///< up, down, up, ...
  int points_per_sweep = 60;
  double span_widths = 10.0;          ///< sweep span in widths (widened by the backbone shift)
  double dwell_time_constants = 7.0;  ///< dwell per point in amplitude time constants 1/(pi w0)
  double point_interval_s = 0.0;      ///< written time step (0: the simulated dwell)
  unsigned seed = 1;
};

/// The record (t, frequency_hz, x, y, drive) with the truth in its comments.
ResponseRecord simulateResponse(const ResponseSimulatorOptions& o);

}  // namespace cvg_bench
