// How the demodulator colours measurement noise. The chain is linear: a slow sample is
// sum_k h_k x_{nD-k}, h the composite impulse response of the filter stages at the input rate
// (each stage's taps upsampled by the decimation of the stages before it, all convolved) and D the
// total decimation. White noise on f, g (after mixing, white on each channel across the envelope
// band; the 2 W image falls in the stopband) therefore reaches slow samples l apart with the
// correlation
//   rho_l = sum_k h_k h_{k + l D} / sum_k h_k^2,
// the same for q1, p1, q2, p2 and none between them. Fits of demodulated records need it: the
// output-error covariance with white residuals is ~15 % too narrow (docs/validation.md).
#pragma once

#include <vector>

#include "cvg_bench/core/demod/demodulator.h"

namespace cvg_bench {

/// Metadata key of a demodulated record holding rho_1 rho_2 ... (space-separated).
constexpr const char* kNoiseCorrelationKey = "noise_correlation";

/// rho_1, rho_2, ... of the header for a filter chain, up to the last lag with |rho| >= cutoff.
std::vector<double> outputNoiseCorrelation(const std::vector<FilterStage>& stages,
                                           double cutoff = 1e-3);

/// The correlations stored under kNoiseCorrelationKey (empty when absent). InputError when the
/// entry is not a list of finite numbers in (-1, 1).
std::vector<double> noiseCorrelationFromMetadata(const RecordMetadata& metadata);

}  // namespace cvg_bench
