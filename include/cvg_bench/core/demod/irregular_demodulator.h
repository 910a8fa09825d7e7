// Windowed least-squares demodulator for irregularly sampled raw signals (camera-tracked
// pendulums, dropped samples, jittered timestamps), same convention as (2.4):
//   f = p1 sin(W t) + q1 cos(W t),  g = p2 sin(W t) + q2 cos(W t).
// For each output time t_c (a grid of step 1 / output_rate_hz aligned to multiples of it), the
// samples with |t - t_c| <= window_s / 2 are fitted, f and g separately, by QR
// (ColPivHouseholderQR) on the columns
//   cos(W t), sin(W t)                           -> q1, p1 (q2, p2) at t_c
//   tau cos(W t), tau sin(W t), tau = t - t_c    -> envelope slope (fit_envelope_slope)
//   1, tau                                       -> offset and offset drift (fit_offset[_slope])
// with the phase W t taken from each sample's own timestamp (referencePhase, exact over hours).
// With the envelope slope fitted, a linearly varying envelope is returned exactly at t_c however
// the samples fall in the window. Standard errors come from the window's residual variance and
// (A^T A)^-1 via R. A window with fewer than min_samples samples, or rank-deficient (e.g. samples
// at only two phases), gives no output and is reported.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "cvg_bench/core/io/records.h"
#include "cvg_bench/core/io/sample_validator.h"

namespace cvg_bench {

struct IrregularDemodulatorOptions {
  /// Reference frequency W [rad/s], > 0.
  double omega_rad_s = 0.0;
  /// Output rate [Hz], > 0: output times are the multiples of 1 / output_rate_hz.
  double output_rate_hz = 10.0;
  /// Fit window length [s]; 0 = 2 / output_rate_hz. Should span several periods 2 pi / W.
  double window_s = 0.0;
  /// Minimum samples per window; 0 = number of fitted columns + 4.
  int min_samples = 0;
  /// Fit the envelope's slope inside the window (exact for linear envelopes).
  bool fit_envelope_slope = true;
  /// Fit a constant offset of f, g.
  bool fit_offset = true;
  /// Also fit a linear drift of the offset (needs fit_offset).
  bool fit_offset_slope = false;

  std::vector<std::string> validate() const;
};

struct IrregularDemodResult {
  /// Slow record: t = window centres, q = (q1, p1, q2, p2); omega = W; metadata mode free_decay.
  SlowRecord record;
  /// Standard errors of (q1, p1, q2, p2) per output sample.
  std::vector<Eigen::Vector4d> std_error;
  /// Samples per window used, per output sample.
  std::vector<int> n_samples;
  /// Centres of windows that gave no output (too few samples or rank-deficient).
  std::vector<double> skipped_window_times;
  int n_too_few = 0;         ///< windows with fewer than min_samples samples
  int n_rank_deficient = 0;  ///< windows whose fit was rank-deficient
  /// Input screening: non_finite, duplicate_timestamp, non_monotonic counts (others unused).
  SampleCounters counters;
};

/// Demodulates a raw record with irregular timestamps. InputError for invalid options, sizes
/// that differ, or when no window gives an output.
IrregularDemodResult demodulateIrregular(const RawRecord& raw,
                                         const IrregularDemodulatorOptions& options);

}  // namespace cvg_bench
