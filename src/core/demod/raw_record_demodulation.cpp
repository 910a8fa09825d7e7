#include "cvg_bench/core/demod/raw_record_demodulation.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "cvg_bench/core/demod/demodulator.h"
#include "cvg_bench/core/demod/frequency_estimator.h"
#include "cvg_bench/core/demod/irregular_demodulator.h"
#include "cvg_bench/core/demod/raw_glitches.h"

namespace cvg_bench {

SlowRecord demodulateRawRecord(const RawRecord& input, double omega_rad_s,
                               std::vector<std::string>& notes) {
  RawRecord raw = input;
  std::ostringstream s;
  s << std::setprecision(8) << "input " << raw.source << " is a raw t,f,g record";
  const auto columns = raw.metadata.find("columns_read_as");
  if (columns != raw.metadata.end()) s << " (" << columns->second << ")";
  if (raw.n_reordered > 0 || raw.n_duplicates_dropped > 0)
    s << " (" << raw.n_reordered << " rows reordered, " << raw.n_duplicates_dropped
      << " duplicated timestamps dropped)";
  double omega = omega_rad_s > 0.0 ? omega_rad_s : raw.omega_rad_s;
  const bool estimated = !(omega > 0.0);
  if (estimated) omega = estimateFrequency(raw.t_s, raw.f, raw.g).omega_rad_s;
  // Bad single samples out first (raw_glitches.h); W is estimated again on what is left.
  const RawGlitchReport glitches = removeRawGlitches(raw, omega);
  if (glitches.any()) notes.push_back(glitches.describe());
  if (estimated) {
    const FrequencyEstimate fe = estimateFrequency(raw.t_s, raw.f, raw.g);
    omega = fe.omega_rad_s;
    s << "; reference frequency estimated: W = " << omega << " +/- " << fe.std_rad_s << " rad/s ("
      << fe.method << ")";
  }
  const double f_ref_hz = omega / (2.0 * M_PI);
  const SamplingSummary sampling = summarizeSampling(raw.t_s);
  SlowRecord slow;
  if (sampling.uniform && sampling.median_interval_s > 0.0) {
    DemodulatorOptions d;
    d.omega_rad_s = omega;
    d.sample_rate_hz = 1.0 / sampling.median_interval_s;
    // The slow rate stays below the reference frequency, so that the envelope filter's stopband
    // (half the slow rate) lies below the 2W term it must remove.
    d.output_rate_hz = std::min({100.0, d.sample_rate_hz / 4.0, f_ref_hz});
    slow = demodulateUniform(raw, d);
    s << "; demodulated at W = " << omega << " rad/s (uniform FIR path, " << d.output_rate_hz
      << " Hz requested)";
  } else {
    IrregularDemodulatorOptions d;
    d.omega_rad_s = omega;
    d.output_rate_hz = std::min(100.0, f_ref_hz);
    slow = demodulateIrregular(raw, d).record;
    s << "; demodulated at W = " << omega
      << " rad/s by windowed least squares (irregular timestamps; "
      << (d.output_rate_hz < 100.0 ? "one output a period, window 2 periods"
                                   : "100 outputs a second, window 20 ms")
      << ")";
  }
  slow.source = raw.source;
  slow.omega_rad_s = omega;
  s << " into " << slow.size() << " slow samples";
  notes.push_back(s.str());
  return slow;
}

}  // namespace cvg_bench
