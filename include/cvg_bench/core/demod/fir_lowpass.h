// Linear-phase anti-alias low-pass FIR (Kaiser-windowed sinc) and a streaming polyphase decimator
// for the demodulator's four baseband channels (2f cos, 2f sin, 2g cos, 2g sin).
//
// Design guarantee (checked in code at design time and in fir_lowpass_test.cpp):
//   passband [0, passband_hz]:           |H(f) - 1| <= 10^(-attenuation_db / 20)
//   stopband [stopband_hz, rate / 2]:    |H(f)|     <= 10^(-attenuation_db / 20)
// H is the zero-phase (real) response; the filter has an odd number of symmetric taps, so its group
// delay is exactly (n_taps - 1) / 2 samples and its centre is a sample. DC gain is exactly 1 (taps
// normalized to sum 1), so a constant baseband value passes unchanged.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace cvg_bench {

struct LowpassSpec {
  /// Input sample rate [Hz], > 0.
  double sample_rate_hz = 0.0;
  /// Passband edge [Hz], 0 <= passband_hz < stopband_hz.
  double passband_hz = 0.0;
  /// Stopband edge [Hz], <= sample_rate_hz / 2.
  double stopband_hz = 0.0;
  /// Stopband attenuation and passband ripple bound [dB], 20..300.
  double attenuation_db = 120.0;
  /// Upper bound on the number of taps (design fails with InputError beyond it), >= 3.
  int max_taps = 200001;

  std::vector<std::string> validate() const;
};

/// Kaiser window shape parameter beta for a given attenuation [dB] (Kaiser's formula).
double kaiserBeta(double attenuation_db);

/// Designs the low-pass: Kaiser's length estimate, then the response is evaluated on a grid that
/// resolves every side lobe near the band edges and the length grown until the guarantee of the
/// header holds. Throws InputError (all validate() problems, or more than max_taps needed).
std::vector<double> designKaiserLowpass(const LowpassSpec& spec);

/// Zero-phase response H(f) = sum_k h_k cos(2 pi f (k - c) / rate) of symmetric taps, c = centre.
double lowpassResponse(const std::vector<double>& taps, double f_hz, double sample_rate_hz);

/// Worst passband deviation max |H - 1| on [0, passband] and worst stopband gain max |H| on
/// [stopband, rate/2], on a dense grid (every side lobe near the edges resolved).
struct LowpassCheck {
  double passband_deviation = 0.0;
  double stopband_gain = 0.0;
};
LowpassCheck checkLowpass(const std::vector<double>& taps, const LowpassSpec& spec);

/// Streaming polyphase decimator of four interleaved channels sharing one timestamp per sample:
/// only the kept outputs are computed (every `decimation`-th full window), using the tap symmetry.
/// An output is produced only from a full window (no start-up transient); its time is the
/// timestamp of the window's centre sample, i.e. group delay corrected exactly.
class PolyphaseDecimator4 {
 public:
  /// taps: odd length, symmetric; decimation >= 1. InputError otherwise.
  PolyphaseDecimator4(std::vector<double> taps, int decimation);

  /// Forgets all history (the next output needs a full window again).
  void reset();

  /// Where to write n new samples (n <= maxChunk()): 4 * n interleaved values and n timestamps.
  struct InputSlot {
    double* values;
    double* times;
  };
  InputSlot prepareInput(size_t n);
  /// Filters the n samples written through prepareInput; appends each output's 4 values to
  /// out_values and its time to out_times.
  void commit(size_t n, std::vector<double>& out_values, std::vector<double>& out_times);

  /// Convenience: copies n interleaved samples in (any n) and commits.
  void push(const double* values, const double* times, size_t n, std::vector<double>& out_values,
            std::vector<double>& out_times);

  size_t numTaps() const { return taps_.size(); }
  int decimation() const { return decimation_; }
  size_t maxChunk() const { return chunk_; }
  const std::vector<double>& taps() const { return taps_; }

 private:
  void compact();

  std::vector<double> taps_;
  std::vector<double> half_taps_;  // h_0 .. h_{L-1}, then the centre tap h_L
  int decimation_;
  size_t chunk_;
  std::vector<double> buf_;    // 4 values per sample
  std::vector<double> times_;  // one per sample
  size_t len_ = 0;             // samples held
  size_t next_end_ = 0;        // buffer index of the last sample of the next output's window
};

}  // namespace cvg_bench
