// The one path from a raw t,f,g record to the slow record q = (q1, p1, q2, p2) that `identify`
// and `explain` analyse (issue #25: both read a raw record the same way, for kHz resonators and
// for a pendulum of a few seconds' period alike).
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/io/records.h"

namespace cvg_bench {

/// Reference frequency W: `omega_rad_s` when > 0, else the record's `# omega:`, else estimated
/// from f, g (estimateFrequency; again after bad single samples are left out, raw_glitches.h,
/// which get a note of their own). Uniform timestamps: the FIR demodulator at a slow rate of
/// min(100 Hz, fs / 4, W / 2 pi); irregular ones: windowed least squares at min(100 Hz, W / 2 pi)
/// (one output a period for slow oscillators) with a window of two outputs. Appends one note that
/// says what was done (rows repaired, W and where it came from, the path, the slow samples).
SlowRecord demodulateRawRecord(const RawRecord& raw, double omega_rad_s,
                               std::vector<std::string>& notes);

}  // namespace cvg_bench
