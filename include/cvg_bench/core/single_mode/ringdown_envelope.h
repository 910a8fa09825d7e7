// The log-amplitude envelope of a single-channel ring-down, whatever the file held: a linear
// amplitude (ln A), a power in dB (ln A = P_dB ln(10) / 20: power ~ A^2, any dB offset is a
// constant in ln A and drops out of Q), or a raw waveform f(t) demodulated first at the mode
// frequency (demodulator.h with g = 0; A = sqrt(q1^2 + p1^2), the van der Pol amplitude of (2.4)).
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/io/ringdown_record.h"

namespace cvg_bench {

struct RingdownEnvelope {
  std::vector<double> t_s;
  std::vector<double> log_amplitude;  ///< ln A [ln of the file's unit]; NaN where not finite
  double frequency_hz = 0.0;          ///< mode frequency [Hz] (0 unknown)
  bool from_db = false;               ///< the file held a dB power
  std::vector<std::string> notes;     ///< what was done (demodulation, conversions)
  size_t size() const { return t_s.size(); }
};

/// The envelope rate of a raw waveform: min(max_output_rate_hz, sample rate /
/// min_decimation, mode frequency / carrier_divisor). All three set by hand with the ring-downs
/// (commit 3dbfdf5), no recorded evidence; the demodulator itself needs the rate under twice the
/// mode frequency (its mixing image) and the sample rate.
struct RingdownEnvelopeOptions {
  /// The envelope's sample rate at most [Hz]: "fast enough for the decay" (the demodulator's
  /// default output rate).
  double max_output_rate_hz = 100.0;
  /// The sample rate over the envelope rate at least [-].
  double min_decimation = 8.0;
  /// The mode frequency over the envelope rate at least [-]: "well below the carrier".
  double carrier_divisor = 4.0;
};

/// frequency_hz > 0 overrides the record's; a raw waveform without any frequency has its
/// frequency estimated (frequency_estimator.h) and the notes say so.
RingdownEnvelope ringdownEnvelope(const RingdownRecord& record, double frequency_hz = 0.0,
                                  const RingdownEnvelopeOptions& options = {});

}  // namespace cvg_bench
