// Estimation of the reference frequency W from raw f, g when it is not given (free decay), on
// uniform or irregular timestamps.
//  1. Coarse: the record (or its first max_fft_samples / oversampling samples) is put on a uniform
//     grid of the median interval (linear interpolation; identity for uniform data), the mean
//     removed, zero-padded `oversampling` times, FFT (Eigen's kissfft); the peak of |F|^2 + |G|^2
//     in [min_hz, max_hz] is refined by parabolic interpolation of log power.
//  2. Fine: nonlinear least squares (Gauss-Newton, steps by QR) of the common-frequency sinusoids
//       f = a_f cos(W tau) + b_f sin(W tau) + c_f,  g = a_g cos(W tau) + b_g sin(W tau) + c_g,
//     tau = t - t_mid, on the raw timestamps, over a span growing 4x per stage from the coarse
//     segment to the whole record (each stage starts well inside the next one's capture range).
//  3. Uncertainty: std of W from sigma^2 (J^T J)^-1 at the optimum, sigma^2 = RSS / (2N - 7).
//     It assumes white noise and constant amplitudes; a decaying envelope (free decay) leaves W
//     unbiased for a symmetric window but inflates sigma, so the std is conservative there.
#pragma once

#include <string>
#include <vector>

namespace cvg_bench {

struct FrequencyEstimatorOptions {
  /// Lowest frequency searched [Hz]; 0 = 3 / record length.
  double min_hz = 0.0;
  /// Highest frequency searched [Hz]; 0 = Nyquist of the median interval.
  double max_hz = 0.0;
  /// Zero-padding factor of the coarse FFT, 1..64.
  int oversampling = 4;
  /// Largest FFT length (samples after padding), >= 1024.
  int max_fft_samples = 1 << 21;
  /// Gauss-Newton iterations per stage, >= 1.
  int max_iterations = 20;

  std::vector<std::string> validate() const;
};

struct FrequencyEstimate {
  double omega_rad_s = 0.0;   ///< estimated W [rad/s]
  double std_rad_s = 0.0;     ///< its standard error [rad/s]
  double coarse_rad_s = 0.0;  ///< the FFT peak before refinement [rad/s]
  double amplitude = 0.0;     ///< sqrt(a_f^2 + b_f^2 + a_g^2 + b_g^2) of the fit
  double residual_rms = 0.0;  ///< sigma of the fit
  size_t n_samples = 0;
  std::string method;  ///< what was done, for the tool's `# ...` lines
};

/// InputError for invalid options, fewer than 16 samples, non-increasing or non-finite data, or
/// no peak in the band; AnalysisError when the refinement diverges.
FrequencyEstimate estimateFrequency(const std::vector<double>& t_s, const std::vector<double>& f,
                                    const std::vector<double>& g,
                                    const FrequencyEstimatorOptions& options = {});

}  // namespace cvg_bench
