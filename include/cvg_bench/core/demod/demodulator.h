// Demodulator for uniformly sampled raw signals: f(t), g(t) -> slow envelopes q = (q1, p1, q2, p2)
// with exactly the convention of the van der Pol substitution (2.4):
//   f = p1 sin(W t) + q1 cos(W t),   g = p2 sin(W t) + q2 cos(W t),
// so q1 = LPF(2 f cos W t), p1 = LPF(2 f sin W t), q2 = LPF(2 g cos W t), p2 = LPF(2 g sin W t),
// W = the reference frequency (omega for free decay, omega0 for forced oscillations).
//
// How:
//  1. I/Q mixing with a reference whose phase is W * t of each sample's own TIMESTAMP. The phase is
//     computed exactly (W t reduced modulo 2 pi in long double: ~1e-9 rad after 10 h at 1e5 rad/s)
//     every `anchor_interval` samples and carried between anchors by a complex rotation whose step
//     is taken from the anchors' timestamps. No drift, no phase jump across batches or hours.
//  2. A linear-phase anti-alias low-pass (Kaiser-windowed sinc designed in code, fir_lowpass.h)
//     with decimation to the slow rate, polyphase (only kept outputs are computed), in one stage or
//     two cascaded stages (chosen automatically for the lowest cost). The whole chain meets, for an
//     envelope component at frequency nu [Hz] (i.e. a signal line at W/2pi +- nu):
//       passband  nu <= passband_hz:           |gain - 1| <= 10^(-attenuation_db/20)
//       stopband  nu >= stopband_hz (aliases included): gain <= 10^(-attenuation_db/20)
//     Defaults: passband 0.2 x output rate, stopband 0.5 x output rate (nothing aliases into
//     [0, output_rate/2]), 120 dB. The mixing image at 2W is in the stopband (validate() checks).
//  3. Each slow sample's time is the timestamp of the physical sample at the filter's centre
//     (group delay corrected exactly, odd symmetric filters). Outputs come only from full windows:
//     after a start or restart the first output appears after latencyS() of data (no transient).
//  4. Bad input goes through SampleValidator (sample_validator.h): dropped and counted by reason.
//     Missing samples (up to gap_periods) are filled from the latest slow output (the envelope at
//     the missing timestamps' own phase) and counted; before the first output of a segment this is
//     impossible and the filter restarts instead. A longer gap restarts the filter; a large jump
//     back in time (bag loop) resets the demodulator. Every restart starts a new `segment`.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cvg_bench/core/demod/fir_lowpass.h"
#include "cvg_bench/core/io/records.h"
#include "cvg_bench/core/io/sample_validator.h"

namespace cvg_bench {

struct DemodulatorOptions {
  /// Reference frequency W [rad/s], > 0 (omega for free decay, omega0 for forced).
  double omega_rad_s = 0.0;
  /// Nominal input sample rate [Hz], > 2 W / (2 pi) (Nyquist).
  double sample_rate_hz = 0.0;
  /// Requested slow output rate [Hz]; the decimation is round(sample_rate_hz / output_rate_hz)
  /// and the actual rate sample_rate_hz / decimation (see Demodulator::outputRateHz()).
  double output_rate_hz = 100.0;
  /// Passband edge of the envelope [Hz]; 0 = 0.2 x actual output rate.
  double passband_hz = 0.0;
  /// Stopband edge of the envelope [Hz]; 0 = 0.5 x actual output rate. Must be below 2W/(2 pi).
  double stopband_hz = 0.0;
  /// Stopband attenuation and passband ripple bound [dB], 20..300.
  double attenuation_db = 120.0;
  /// Timestamp tolerance, fraction of the sample period (SampleValidatorOptions).
  double interval_tolerance = 0.01;
  /// Gap length (in sample periods) that restarts the filter (SampleValidatorOptions).
  double gap_periods = 10.0;
  /// Samples between exact re-anchoring of the reference phase to the timestamps, 4..4096.
  int anchor_interval = 1024;

  std::vector<std::string> validate() const;
};

/// One slow sample: time of the physical sample at the filter centre [s], q = (q1, p1, q2, p2).
struct SlowSample {
  double t_s = 0.0;
  Eigen::Vector4d q = Eigen::Vector4d::Zero();
  uint32_t segment = 0;  ///< increments at every restart (gap, reset, impossible fill)
};

/// One filter stage of the chain.
struct FilterStage {
  LowpassSpec spec;  ///< design spec (rate = this stage's input rate)
  int decimation = 1;
  size_t n_taps = 0;
};

class Demodulator {
 public:
  /// Throws InputError listing every problem of options.validate().
  explicit Demodulator(const DemodulatorOptions& options);
  ~Demodulator();
  Demodulator(Demodulator&&) noexcept;
  Demodulator& operator=(Demodulator&&) noexcept;

  /// Pushes a batch (t [s], f, g of length n; any size, including 0) and appends the slow samples
  /// it completes to `out`. Never throws on bad data: problems are counted (counters()).
  void push(const double* t, const double* f, const double* g, size_t n,
            std::vector<SlowSample>& out);
  void push(const std::vector<double>& t, const std::vector<double>& f,
            const std::vector<double>& g, std::vector<SlowSample>& out);

  /// Clears the filter and the timestamp history (counters are kept; a new segment starts).
  void reset();

  const SampleCounters& counters() const;
  void resetCounters();
  /// Current segment number (0 until the first restart).
  uint32_t segment() const { return segment_; }
  /// Human-readable description of the latest restart/reset ("" when none).
  const std::string& lastEvent() const { return last_event_; }

  const DemodulatorOptions& options() const { return options_; }
  double outputRateHz() const;
  double passbandHz() const { return passband_hz_; }
  double stopbandHz() const { return stopband_hz_; }
  /// Data needed before the first output after a (re)start = total filter length [s].
  double latencyS() const;
  /// Group delay of the chain [s] (output time = input time of the centre sample).
  double groupDelayS() const;
  const std::vector<FilterStage>& stages() const { return stages_; }

 private:
  void restart(const std::string& why);
  void mixAndFilter(const double* t, const double* f, const double* g, size_t n,
                    std::vector<SlowSample>& out);
  bool fillMissing(const AcceptedRun& run, double t_next, std::vector<SlowSample>& out);

  DemodulatorOptions options_;
  double passband_hz_ = 0.0, stopband_hz_ = 0.0;
  std::vector<FilterStage> stages_;
  std::vector<std::unique_ptr<PolyphaseDecimator4>> filters_;
  std::unique_ptr<SampleValidator> validator_;
  std::vector<double> stage_values_[2], stage_times_[2];  // scratch
  uint32_t segment_ = 0;
  bool have_envelope_ = false;
  Eigen::Vector4d last_q_ = Eigen::Vector4d::Zero();
  std::string last_event_;
};

/// Reference phase W t reduced to [0, 2 pi), computed in long double (precise over hours).
double referencePhase(double omega_rad_s, double t_s);

/// Whole-record convenience: demodulates a uniformly sampled raw record. If
/// options.sample_rate_hz is 0 it is taken from the median timestamp interval; if
/// options.omega_rad_s is 0 the record's omega is used. The result carries omega = W and
/// metadata mode = free_decay plus the filter description; counters (optional) get the counts.
/// InputError when the options are invalid or no slow sample results (record too short).
SlowRecord demodulateUniform(const RawRecord& raw, DemodulatorOptions options,
                             SampleCounters* counters = nullptr);

/// Timing of a record's timestamps: used to pick the uniform FIR path or the windowed-LS path.
struct SamplingSummary {
  size_t n = 0;
  double median_interval_s = 0.0;
  /// Fraction of intervals within `tolerance` x median of the median.
  double fraction_on_grid = 0.0;
  /// Fraction of intervals that are whole multiples (>= 2) of the median (dropped samples).
  double fraction_multiple = 0.0;
  /// True when every interval is on the grid or a whole multiple (<= gap_periods) and >= 90 % of
  /// them are single periods: the uniform FIR path applies.
  bool uniform = false;
};
SamplingSummary summarizeSampling(const std::vector<double>& t_s, double tolerance = 0.01,
                                  double gap_periods = 10.0);

}  // namespace cvg_bench
