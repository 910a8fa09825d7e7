// Segmentation of a single-channel ring-down into the driven plateau, the decay and the noise
// floor, with drop-outs marked, so that only the decay above the floor is fitted.
//  1. Drop-outs: non-finite samples, and samples more than max(8 robust sd, 3 dB) below the running
//     median of their neighbours (a detector that lost lock, a spectrum-analyser blank).
//  2. Noise floor: from 25 dB above the median level of the record's last tenth to the end, a
//     straight ln A decay plus an additive floor (the Rice mean of ringdown_models.h) is fitted
//     against the straight decay alone. A floor lies 3 dB or more above the line's continuation
//     at the end and scatters like noise past the line's crossing of it (sd of ln A about a line
//     over 0.2, where Rayleigh noise alone gives 0.64), and either wins (n ln(SSE ratio) > 30) or
//     scatters twice as much as the early decay. The decay span ends where the running median
//     falls to `floor_margin_db` above the floor (the fit includes the floor). A floor above the
//     continuation that scatters but is not confirmed is only suspected: the span stops the margin
//     above it and no floor is claimed. A decay that slows without that scatter (a damping law in
//     A, the slower of two modes) is no floor.
//  3. Drive switch-off: the plateau level is the median of the smoothed envelope over the first
//     twentieth; the decay starts where the envelope first falls max(6 sd, 0.1 dB) below its 5th
//     percentile there (a beating plateau dips below its median). A
//     plateau needs that crossing late enough and the envelope before it not falling steadily
//     (90 % of its differences over a tenth of the stretch negative and the mean rate over 0.3 of
//     the rate after the crossing); else the decay starts at the first sample.
//     Detector settling: the span then starts at the drive-off plus twice the time the local decay
//     rate takes to peak within the first 3 dB (a lock-in's low-pass rounds the corner; at most the
//     first 3 dB are skipped).
//  4. Refusal: under 3 dB (or 10 robust sd) of decay, or under 8 samples in the span.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "cvg_bench/core/single_mode/ringdown_envelope.h"

namespace cvg_bench {

struct RingdownSegmentationOptions {
  /// Fit down to this far above the noise floor [dB], 3..40.
  double floor_margin_db = 10.0;
  /// ... unless the decay rises less than floor_margin_db + short_decay_db above the floor: then
  /// the margin leaves short_decay_db of decay, but is not under min_floor_margin_db [dB].
  double short_decay_db = 10.0;
  double min_floor_margin_db = 4.0;
  /// A drop-out lies at least this far below its neighbours' median [dB] (and 8 robust sd).
  double dropout_depth_db = 3.0;
  /// Minimum decay in the span [dB] for a ring-down to be analysed.
  double min_decay_db = 3.0;
  std::vector<std::string> validate() const;
};

struct RingdownSegment {
  size_t i_start = 0, i_end = 0;  ///< span [i_start, i_end) of envelope samples fitted
  double t_start_s = 0.0, t_end_s = 0.0;
  bool has_plateau = false;
  double drive_off_s = 0.0;          ///< hinge time (= first sample time without a plateau)
  double plateau_log_amplitude = 0;  ///< ln A of the plateau (or the start)
  bool has_floor = false;
  double floor_log_amplitude = 0.0;  ///< ln of the floor's rms amplitude (when has_floor)
  double floor_start_s = 0.0;        ///< where the envelope reaches the floor (when has_floor)
  double floor_margin_db = 0.0;  ///< the span ends this far above a floor (confirmed or suspected)
  /// ln of a floor the decay bends towards but the record holds too little of to confirm (NaN
  /// when none); the span stops the margin above it without claiming a floor.
  double suspected_floor_log_amplitude = std::numeric_limits<double>::quiet_NaN();
  std::vector<bool> dropout;  ///< per envelope sample
  size_t n_dropouts_in_span = 0;
  size_t n_used = 0;          ///< samples in the span that are not drop-outs
  double decay_db = 0.0;      ///< drop of the running median over the span [dB]
  double noise_sd_log = 0.0;  ///< robust sd of ln A from sample-to-sample differences
  std::string why;            ///< the printout/JSON sentence
};

/// Throws AnalysisError("no decay ...") when the record shows no usable decay, InputError when
/// the envelope is too short. db_units: say levels in dB re the file's unit (true for dB input).
RingdownSegment segmentRingdown(const RingdownEnvelope& env,
                                const RingdownSegmentationOptions& options = {});

/// Running median of the finite values in a centred window of `half` samples each side.
std::vector<double> runningMedian(const std::vector<double>& y, const std::vector<bool>& skip,
                                  int half);

}  // namespace cvg_bench
