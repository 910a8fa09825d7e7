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

/// frequency_hz > 0 overrides the record's; a raw waveform without any frequency has its
/// frequency estimated (frequency_estimator.h) and the notes say so.
RingdownEnvelope ringdownEnvelope(const RingdownRecord& record, double frequency_hz = 0.0);

}  // namespace cvg_bench
