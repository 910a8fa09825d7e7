// The part of a real ring-down export that holds the last ring-down (docs/validation_ringdown.md,
// "Real records"). Instrument files hold more than plateau-decay-floor: the floor before the drive
// comes on and a ramp-up, a drive that toggles, a step at switch-off (the drive's own leakage
// leaving the analyser's band), and after the decay a mode that drifts out of the band (a drop of
// tens of dB in a few samples), a detector that switches range or stops (a step into a flat or
// smooth line), a second burst. The segmentation (ringdown_segmentation.h) reads a plateau at the
// head and a decay then a floor after it; this window gives it that shape:
//  1. Steps: a sharp change of the smoothed level (medians of `step_half` samples either side
//     differ by >= step_db and by step_min_sharpness local difference sd, while each side's own
//     change over the same number of samples is under 1 / step_side_divisor of it); and rising
//     ramps, the same over ramp_scales (up to ramp_scale) times as many samples for rises of
//     end_step_db or more (the drive coming on through a detector's filter; a fall that fast may
//     be the decay itself).
//  2. The drive level is the peak of the smoothed envelope. A step down that starts within
//     near_top_db of it after the peak is a switch-off step: the window starts after it. A step up
//     back to within near_top_db is the drive coming on again: the window restarts there.
//  2b. When the drive came on again, a ring-down before it that falls more than
//     earlier_burst_margin_db further than the last one is read instead (a drive pulse, or a
//     burst that steps out of the band, leaves only a stub of decay).
//  3. A record that starts more than start_below_db under the drive level (it begins at the floor
//     or on the ramp-up) starts at its last rise through start_rise_fraction near_top_db below
//     the peak.
//  4. Any other step after the decay has begun (over near_top_db down) ends the window before it
//     when it is large (end_step_db) or sharp (end_step_sharpness local sd).
//  6. (Before 5.) A tail that is noiseless to the record's end (roughness under tail_roughness_db
//     and tail_roughness_ratio times under the stretch before it) is an appended curve: the
//     window ends there.
//  5. In a record that started under the drive level (3), a plateau longer than plateau_fraction
//     of the rest is cut to that length before the last sample within off_below_db of the peak.
#pragma once

#include <string>
#include <vector>

namespace cvg_bench {

struct RingdownWindowOptions {
  /// A step changes the smoothed level by at least this [dB] (real out-of-band drops are 20-75 dB,
  /// switch-off steps 8-60 dB on the development set; the generator's smooth detection-gain
  /// steps of 6-12 dB over 3-8 % of the span are not sharp and never qualify).
  double step_db = 8.0;
  /// A step that ends the window (after the decay began) is at least this large [dB], or at
  /// least end_step_sharpness local difference sd: a noise floor's own jumps (8-10 dB at 4-10 sd
  /// in the generator's lock-in floors) must not end it.
  double end_step_db = 20.0;
  double end_step_sharpness = 12.0;
  /// Samples on each side whose median is compared (and over which each side must be flat).
  int step_half = 3;
  /// A step's jump is at least this many local sd of the sample-to-sample differences [sd]: the
  /// "4 local difference sd" of step 1. Set by hand with the window (commit 4a9837c: the window
  /// as a whole took the tuning part from 47 to 83 of 154 clean records within 5 %); no recorded
  /// evidence for the value itself.
  double step_min_sharpness = 4.0;
  /// Each side's own change over step_half samples is under the jump divided by this [-] (step
  /// 1: "under a third of it"). Set by hand (commit 4a9837c), no recorded evidence.
  double step_side_divisor = 3.0;
  /// The local sd of the differences is taken over this many samples either side of a step, the
  /// jump itself left out [samples]. Set by hand (commit 3d3ff4f; it was 2 step_half samples
  /// before), no recorded evidence.
  int step_scatter_half = 10;
  /// Rising ramps: the same comparison over 4 and 10 times step_half samples (up to ramp_scale
  /// times) finds rises whose ramp takes up to that many samples (the drive toggled on through a
  /// detector's filter: D197 of the development set, 60 dB over ~24 samples), when they raise the
  /// level by end_step_db. Falls are not read so (a fast fall may be the decay itself).
  int ramp_scale = 10;
  /// The multiples of step_half over which rising ramps are read, in increasing order (those over
  /// ramp_scale are skipped): 12 and 30 samples at step_half = 3, for D197 of the development set
  /// (commit a42d595; docs/validation_ringdown_real.md, 29 Nov evening: D197 Q 0.36x -> 1.02x).
  std::vector<int> ramp_scales = {4, 10};
  /// A ramp's ends are the last sample at the left level and the first at the right one, within
  /// this fraction of the jump [-]. Set by hand (commit a42d595), no recorded evidence.
  double ramp_end_tolerance = 0.1;
  /// Within this of the peak level [dB]: still the drive level (switch-off, drive on again).
  double near_top_db = 6.0;
  /// A ring-down before a re-excitation is read instead of the last when it falls this much
  /// further [dB] (the development set's drive pulses leave 12-15 dB stubs after 55-60 dB decays).
  double earlier_burst_margin_db = 20.0;
  /// A record whose first 2 % lie this far under the peak [dB] starts before the drive.
  double start_below_db = 10.0;
  /// Step 3's head, compared with the drive level, is a head_divisor-th of the record (2 %), at
  /// least min_head_samples samples. Set by hand (commit 4a9837c), no recorded evidence.
  size_t head_divisor = 50;
  long min_head_samples = 5;
  /// Step 3: a record that starts under the drive level is read from its last rise through
  /// start_rise_fraction times near_top_db below the peak [-] (3 dB at the defaults:
  /// docs/validation_ringdown_real.md, "What was built"). Set by hand (commit 4a9837c), no
  /// recorded evidence.
  double start_rise_fraction = 0.5;
  /// The drive level is held while the smoothed envelope is within this of its peak [dB].
  double off_below_db = 3.0;
  /// A plateau longer than this fraction of the rest of the window is cut to it (the generator's
  /// plateaus are 3-15 % of the decay and are never cut).
  double plateau_fraction = 0.2;
  /// Step 5: a cut plateau keeps at least this many samples. Set by hand (commit 4a9837c), no
  /// recorded evidence.
  size_t min_plateau_samples = 8;
  /// A tail whose roughness (median |second difference|) stays under this [dB] to the end, 30
  /// times smoother than what precedes it, is no measurement (the 750-point exports of the
  /// development set end in such curves at 1e-4..5e-3 dB; their floors are 0.2-3 dB, their decays
  /// down to the 0.005 dB quantum of the export near the top, but never 30 times under what
  /// precedes them).
  double tail_roughness_db = 0.01;
  /// Step 6: the roughness is the median |second difference| over 2 roughness_half + 1 samples.
  /// Set by hand (commit 3d3ff4f), no recorded evidence.
  long roughness_half = 5;
  /// Step 6: a noiseless tail covers a tail_divisor-th of the window (at least min_tail_samples
  /// samples) and is compared with as many samples before it. Set by hand (commit 3d3ff4f), no
  /// recorded evidence.
  size_t tail_divisor = 10;
  size_t min_tail_samples = 10;
  /// Step 6: a noiseless tail lies this far below the peak [dB]. Set by hand (commit 3d3ff4f), no
  /// recorded evidence.
  double tail_below_peak_db = 10.0;
  /// Step 6: the stretch before a noiseless tail is at least this many times rougher [-]: the
  /// appended curves of the 750-point development exports (1e-4..5e-3 dB) against their floors
  /// (0.2-3 dB) and decays (see tail_roughness_db; commit 3d3ff4f).
  double tail_roughness_ratio = 30.0;
  /// The running median that smooths the level has the half-width of a smooth_divisor-th of the
  /// record, at least min_smooth_half samples. Set by hand (commit 4a9837c), no recorded evidence.
  size_t smooth_divisor = 200;
  int min_smooth_half = 2;
  /// A record under this many samples is kept whole (no window is read). Set by hand (commit
  /// 4a9837c), no recorded evidence.
  size_t min_record_samples = 16;
  /// A window under a min_window_divisor-th of the record or min_window_samples samples is no
  /// window (the whole record is kept). Set by hand (commit 3d3ff4f), no recorded evidence.
  size_t min_window_divisor = 20;
  size_t min_window_samples = 16;
};

struct RingdownWindow {
  size_t first = 0, last = 0;  ///< samples [first, last) hold the ring-down
  std::string why;             ///< empty when the whole record is kept
};

/// t: sample times, y: ln A (NaN where not finite).
RingdownWindow findRingdownWindow(const std::vector<double>& t, const std::vector<double>& y,
                                  const RingdownWindowOptions& options = {});

}  // namespace cvg_bench
