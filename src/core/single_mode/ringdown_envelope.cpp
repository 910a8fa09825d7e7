#include "cvg_bench/core/single_mode/ringdown_envelope.h"

#include <cmath>
#include <limits>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/demod/demodulator.h"
#include "cvg_bench/core/demod/frequency_estimator.h"

namespace cvg_bench {

RingdownEnvelope ringdownEnvelope(const RingdownRecord& record, double frequency_hz,
                                  const RingdownEnvelopeOptions& options) {
  RingdownEnvelope env;
  env.frequency_hz = frequency_hz > 0.0 ? frequency_hz : record.frequency_hz;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (record.kind == RingdownValueKind::kAmplitude || record.kind == RingdownValueKind::kPowerDb) {
    env.t_s = record.t_s;
    env.log_amplitude.resize(record.size());
    env.from_db = record.kind == RingdownValueKind::kPowerDb;
    const double db_to_ln = 1.0 / kDbPerNeper;
    for (size_t i = 0; i < record.size(); ++i) {
      const double v = record.value[i];
      if (env.from_db)
        env.log_amplitude[i] = std::isfinite(v) ? v * db_to_ln : nan;
      else
        env.log_amplitude[i] = std::isfinite(v) && v > 0.0 ? std::log(v) : nan;
    }
    if (env.from_db)
      env.notes.push_back("power in dB read as 20 log10(amplitude) + offset (offset drops out)");
    return env;
  }
  // Raw waveform: demodulate one channel (g = 0) at the mode frequency.
  RawRecord raw;
  raw.t_s = record.t_s;
  raw.f = record.value;
  raw.g.assign(record.size(), 0.0);
  raw.source = record.source;
  double omega = 2.0 * M_PI * env.frequency_hz;
  std::ostringstream note;
  if (!(omega > 0.0)) {
    const FrequencyEstimate fe = estimateFrequency(raw.t_s, raw.f, raw.g);
    omega = fe.omega_rad_s;
    env.frequency_hz = omega / (2.0 * M_PI);
    note << "mode frequency estimated from the waveform (" << fe.method << "): ";
  }
  const SamplingSummary sampling = summarizeSampling(raw.t_s);
  if (!sampling.uniform)
    throw InputError(record.source +
                     ": raw ring-down waveform needs uniform timestamps (demodulator.h)");
  DemodulatorOptions o;
  o.omega_rad_s = omega;
  o.sample_rate_hz = 1.0 / sampling.median_interval_s;
  // Slow rate: well below the carrier, fast enough for the decay (default 100 Hz, capped).
  o.output_rate_hz = std::min(options.max_output_rate_hz,
                              std::min(o.sample_rate_hz / options.min_decimation,
                                       omega / (2.0 * M_PI) / options.carrier_divisor));
  const SlowRecord slow = demodulateUniform(raw, o);
  env.t_s = slow.t_s;
  env.log_amplitude.resize(slow.size());
  for (size_t i = 0; i < slow.size(); ++i) {
    const double a = std::hypot(slow.q[i][0], slow.q[i][1]);
    env.log_amplitude[i] = a > 0.0 ? std::log(a) : nan;
  }
  note << "raw waveform demodulated at " << env.frequency_hz << " Hz to " << o.output_rate_hz
       << " Hz envelope samples (FIR demodulator, g = 0)";
  env.notes.push_back(note.str());
  return env;
}

}  // namespace cvg_bench
