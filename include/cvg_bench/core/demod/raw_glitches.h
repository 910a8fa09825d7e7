// Single bad samples in a raw t,f,g record (a camera's skipped or misread frame, an ADC spike)
// found before demodulation (issue #25: one glitch must not flip explain's verdict).
//
// The speed of a step between neighbouring samples, |(f,g)_{i+1} - (f,g)_i| / (t_{i+1} - t_i),
// is at most W A for an oscillation of amplitude A at W (plus noise). A step is implausible when
// it exceeds L = 3 max(W A95, v99): A95 the 95th percentile of the distance from the median
// point, v99 the 99th percentile of the step speeds (the noise's share in a noisy record); both
// quantiles leave a few per cent of bad samples out of the scale.
// - a spike: a sample both of whose steps are implausible while the step that skips it is not:
//   the sample is left out;
// - a start-up or end glitch: an implausible step within the first or last 1 % of the samples
//   (at least 10): the samples before (after) it are left out;
// - any other implausible step (a jump: tracking lost, a gap) is kept and reported with its time.
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/io/records.h"

namespace cvg_bench {

struct RawGlitchReport {
  std::vector<double> spike_times_s;  ///< samples left out as spikes
  int head_dropped = 0, tail_dropped = 0;
  std::vector<double> jump_times_s;  ///< implausible steps kept (start of the step)
  double speed_limit = 0.0;          ///< L [amplitude units / s]
  bool any() const {
    return !spike_times_s.empty() || head_dropped > 0 || tail_dropped > 0 || !jump_times_s.empty();
  }
  /// One sentence for the notes ("" when nothing was found).
  std::string describe() const;
};

/// Removes spikes and start-up/end glitches from `raw` in place (W = omega_rad_s > 0).
RawGlitchReport removeRawGlitches(RawRecord& raw, double omega_rad_s);

}  // namespace cvg_bench
