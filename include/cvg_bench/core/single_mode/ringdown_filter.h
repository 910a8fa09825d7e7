// The detector's low-pass filter of a single-channel ring-down (a lock-in's output filter: n equal
// real poles of time constant T acting on the complex demodulated signal), estimated from a part
// of the record the damping law does not touch: the noise floor. White noise at the detector input
// leaves the filter's shape in the floor's correlation: for circular Gaussian z the power P = |z|^2
// has the autocorrelation corr(P(t), P(t + s)) = rho_n(s / T)^2 exactly, rho_n the normalized
// autocorrelation of the filter's impulse response s^{n-1} e^{-s/T}:
//   rho_1 = e^{-x}, rho_2 = (1 + x) e^{-x}, rho_3 = (1 + x + x^2/3) e^{-x},
//   rho_4 = (1 + x + 2 x^2/5 + x^3/15) e^{-x}   (x = s / T).
// The floor stretch starts where the decay's straight continuation has fallen 6 dB below the floor
// (its residual signal power is removed by a fit c0 + c1 e^{-2 g t}); the empirical autocorrelation
// of P over lags 1..K (K: where it falls under 0.05) is fitted by (rho_n^2 - b) / (1 - b) for
// n = 1..4 and T on a log grid refined by golden section (b >= 0 the bias of a correlation taken
// about a fitted mean, at most 4 correlation times over the stretch's length); the order with the
// smallest sum of squares wins.
//
// The filtered envelope model (ringdownFilteredLogAmplitude): the detector input is the plateau
// level A(t_off) before the drive-off t_off and the damping law A(t) after it; the output is that
// input through the n-pole cascade (each stage y' = (x - y) / T, exact for input linear between
// grid points; grid step T / 8), started settled on the plateau. With the filter in the model the
// fit can start at the plateau, so the first decibels after the drive-off (where a damping law in
// A^2 spends its extra rate) are fitted instead of skipped.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "cvg_bench/core/single_mode/ringdown_envelope.h"
#include "cvg_bench/core/single_mode/ringdown_fit.h"
#include "cvg_bench/core/single_mode/ringdown_segmentation.h"

namespace cvg_bench {

struct RingdownDetectorFilter {
  bool found = false;
  int order = 0;                 ///< number of equal real poles (1..4)
  double time_constant_s = 0.0;  ///< T of each pole [s]
  double fit_rms = 0.0;          ///< rms misfit of the power autocorrelation
  int n_samples = 0;             ///< floor samples used
  int n_lags = 0;                ///< autocorrelation lags fitted
  std::string source;            ///< "noise_floor" or "none"
  std::string why;               ///< the printout/JSON sentence
};

/// The tuned choices of the filter estimate from the noise floor (estimateDetectorFilter). The
/// estimate as a whole came with commit 533c69d (tuning base 41000000: gamma_nl 27 -> 28 of 30).
struct RingdownDetectorFilterOptions {
  /// Orders tried: 1..max_order equal real poles [-]; at most 4, the orders whose closed form
  /// and correlation time are tabulated (on tuning floors of a 2-pole lock-in every order 1..4 was
  /// chosen: docs/validation_ringdown.md, "Detector filter and the amplitude laws").
  int max_order = 4;
  /// The span's last samples whose median gives the level at its end [samples]. Set by hand
  /// (commit 533c69d), no recorded evidence.
  size_t end_level_samples = 9;
  /// The level above the floor at the span's end [dB] when none of those samples is usable. Set
  /// by hand (commit 533c69d), no recorded evidence.
  double default_above_floor_db = 10.0;
  /// The floor stretch starts where the decay's straight continuation lies this far below the
  /// floor [dB] (its residual signal is then removed by a fit). Set by hand (commit 533c69d), no
  /// recorded evidence.
  double below_floor_db = 6.0;
  /// A floor stretch (and its valid samples) must number at least this many [samples]: lowered
  /// from 200 in commit 883fad1 (tuning bases 41/42/43 x 30: gamma_nl 28/29/29, clean false
  /// alarms unchanged at 2/1/1).
  int min_floor_samples = 120;
  /// Sampling is uniform when every interval is within this fraction of the median one [-]. Set
  /// by hand (commit 533c69d), no recorded evidence.
  double sampling_tolerance = 0.01;
  /// The autocorrelation is taken over at most max_lags lags and at most a lags_divisor-th of the
  /// stretch. Set by hand (commit 533c69d), no recorded evidence.
  size_t max_lags = 300;
  size_t lags_divisor = 4;
  /// The lags end where the autocorrelation falls under this (K of the header) [-]. Set by hand
  /// (commit 533c69d), no recorded evidence.
  double correlation_end = 0.05;
  /// Under this correlation at lag 1 the filter is shorter than the sample interval (negligible;
  /// no filter is reported) [-]. Set by hand (commit 533c69d), no recorded evidence.
  double min_lag1_correlation = 0.2;
  /// The log grid of T [samples]: grid_nodes nodes from grid_min_samples to grid_max_samples,
  /// then golden_iterations golden-section steps between the best node's neighbours. Set by hand
  /// (commit 533c69d), no recorded evidence.
  int grid_nodes = 160;
  double grid_min_samples = 0.05;
  double grid_max_samples = 400.0;
  int golden_iterations = 40;
  /// The bias b of an autocorrelation about a fitted mean is at most max_bias [-] and at most
  /// bias_correlation_times correlation times over the stretch's length: the bias fit came with
  /// commit 2119a35 (order 2 modal on 2-pole floors, correlation time 1.01x the truth at the
  /// median), the cap in correlation times with commit 7b54a1c (without it a 1-pole floor's T was
  /// 27 % high). The values themselves were set by hand.
  double max_bias = 0.15;
  double bias_correlation_times = 4.0;
  /// A floor stretch under this many filter lengths (n T) gives an autocorrelation too noisy to
  /// trust [-] (docs/validation_ringdown.md: "8 filter lengths or more"). Set by hand (commit
  /// 533c69d), no recorded evidence.
  double min_filter_lengths = 8.0;
};

/// rho_n(x)^2: the autocorrelation of the power of circular Gaussian noise through n equal real
/// poles at lag x = s / T (order 1..4).
double ringdownFilterPowerCorrelation(int order, double x);

/// The filter from the noise floor (see the header comment); found = false (and why) when the
/// record has no floor stretch of min_floor_samples (120) samples or more, the sampling is not
/// uniform, or the correlation at lag 1 is under min_lag1_correlation (0.2: a filter shorter than
/// the sample interval, negligible). decay_rate_1_s: the decay's amplitude rate (the straight
/// fit's), for the floor stretch's start.
RingdownDetectorFilter estimateDetectorFilter(const RingdownEnvelope& env,
                                              const RingdownSegment& seg, double decay_rate_1_s,
                                              const RingdownDetectorFilterOptions& options = {});

/// ln of the filtered envelope (plus the floor's Rice mean, as ringdownLogAmplitude) at the times
/// t (normalized, increasing) of a law (linear, gamma_nl or gamma_a with p = its parameters at
/// t = 0) switched on at t_off; time_constant in the same normalized unit. Empty when the law has
/// no finite positive amplitude on [t_off, t.back()].
std::vector<double> ringdownFilteredLogAmplitude(const std::string& law, const Eigen::VectorXd& p,
                                                 double t_off, int order, double time_constant,
                                                 const std::vector<double>& t, double floor_rel);

/// A law fitted through the filter from the plateau (or the record's start) to the end of the
/// segment's span: parameters p of the law (normalized as `law_fit`) and t_off.
struct RingdownFilteredFit {
  bool ok = false;
  std::string model;
  Eigen::VectorXd p;  ///< law parameters (ringdownParameterNames) then t_off (normalized)
  double sse_w = 0.0, sse_whitened = 0.0;
  int n = 0;
  double t_start_s = 0.0;  ///< first sample fitted
  double drive_off_s = 0.0;
};

/// The tuned choices of the fit through the filter (fitRingdownThroughFilter), set by hand with
/// it (commit 533c69d); nothing records why these values.
struct RingdownFilteredFitOptions {
  /// The fit starts this many filter lengths (n T) before the segment's drive-off [-].
  double lead_filter_lengths = 12.0;
  /// No fit with under this many samples more than the law's parameters [samples].
  int min_extra_samples = 10;
  /// Iteration cap of each least-squares start (the hand-written loop's of commit 533c69d, kept
  /// with Ceres in 62631c7).
  int max_iterations = 80;
};

/// Fits `law_fit.model` through `filter` over [max(first sample, drive-off - lead_filter_lengths
/// n T), span end), started from law_fit's parameters (and the segment's drive-off). Weights:
/// law_fit's on its span, its first weight before it (the plateau and the corner sit at the top
/// level, where the noise is on the log scale). sse_whitened: the weighted residuals through the
/// AR filter `ar`.
RingdownFilteredFit fitRingdownThroughFilter(const RingdownEnvelope& env,
                                             const RingdownSegment& seg, const RingdownFit& law_fit,
                                             const RingdownDetectorFilter& filter,
                                             const std::vector<double>& ar,
                                             const RingdownFilteredFitOptions& options = {});

}  // namespace cvg_bench
