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
  /// Fit down to this far above the noise floor [dB], 3..40. Set in commit 3dbfdf5; the floor
  /// term of the model is under 1e-5 Np there (docs/validation_ringdown.md, method notes).
  double floor_margin_db = 10.0;
  /// ... unless the decay rises less than floor_margin_db + short_decay_db above the floor: then
  /// the margin leaves short_decay_db of decay, but is not under min_floor_margin_db [dB]. Commit
  /// a42d595 (docs/validation_ringdown_real.md, "29 Nov, evening" item 3: D008's span 3 -> 6.9
  /// dB, Q 1.75x -> 1.35x).
  double short_decay_db = 10.0;
  double min_floor_margin_db = 4.0;
  /// A drop-out lies at least this far below its neighbours' median [dB] (and 8 robust sd). Set
  /// by hand (commit 3dbfdf5), no recorded evidence.
  double dropout_depth_db = 3.0;
  /// Minimum decay in the span [dB] for a ring-down to be analysed. Set by hand (commit
  /// 3dbfdf5), no recorded evidence.
  double min_decay_db = 3.0;
  /// ... and at least this many robust sd of ln A (step 4) [multiples of noise_sd_log]. Set by
  /// hand (commit 3dbfdf5), no recorded evidence.
  double min_decay_sd = 10.0;
  /// A ring-down needs this many samples: in the window's envelope, on the peak's grid, in the
  /// span (step 4) [samples]. Set by hand (commit 3dbfdf5), no recorded evidence.
  size_t min_samples = 8;

  /// Step 1: drop-outs.
  struct Dropouts {
    /// Half-width of the running median the samples are read against [samples] (window 11). Set
    /// by hand (commit 3dbfdf5), no recorded evidence.
    int median_half = 5;
    /// The noise scale is read from differences over the record's first half, at least this many
    /// samples [samples]. Set by hand (commit 3dbfdf5), no recorded evidence.
    size_t min_scale_samples = 8;
    /// A drop-out lies this many robust sd of ln A below the running median, or dropout_depth_db,
    /// whichever is deeper [multiples of noise_sd_log]. Set by hand (commit 3dbfdf5), no recorded
    /// evidence.
    double depth_sd = 8.0;
    /// ... and this many local robust sd (MAD about the running median over 2 local_mad_half + 1
    /// samples) [multiples], so that the Rice dips of additive noise near the floor are not taken
    /// for drop-outs. Set by hand with the local depth (commit 2b6c82b), no recorded evidence for
    /// the values.
    double local_sd = 6.0;
    /// Half-width of that local MAD [samples] (window 21). Commit 2b6c82b, no recorded evidence.
    size_t local_mad_half = 10;
  };
  Dropouts dropouts;

  /// The smoothed envelope the floor, plateau and settling are read on.
  struct Smoothing {
    /// A running median whose half-width is the window's sample count over divisor [1] ...
    size_t divisor = 100;
    /// ... at least this many samples [samples]. Both set by hand (commit 3dbfdf5), no recorded
    /// evidence.
    int min_half = 2;
    /// The smoothed envelope's peak is read on a grid of at most this many samples [samples]. Set
    /// by hand (commit 3dbfdf5, first for a hinge fit since removed, dd42741), no recorded
    /// evidence.
    size_t peak_grid_points = 1500;
  };
  Smoothing smoothing;

  /// Step 2: the noise floor.
  struct NoiseFloor {
    /// The tail level is the median smoothed level over the window's last tail_divisor-th
    /// [1] ...
    size_t tail_divisor = 10;
    /// ... at least this many samples [samples]. Both set by hand (commit 3dbfdf5), no recorded
    /// evidence.
    size_t min_tail_samples = 4;
    /// The floor fit starts stretch_top_db [dB] (or stretch_top_fraction of the peak's drop to
    /// the tail level, whichever is less) above the tail level ...
    double stretch_top_db = 25.0;
    double stretch_top_fraction = 0.75;
    /// ... when the decay goes on to stretch_bottom_db [dB] (or stretch_bottom_fraction of the
    /// drop) above it over more than min_stretch_samples samples. The four levels and the count
    /// were set with the floor test (commit 2cc791c: clean-record Q coverage on the tuning seeds
    /// was 20/40 before it, floors missed); no comparison of other values is recorded.
    double stretch_bottom_db = 10.0;
    double stretch_bottom_fraction = 0.25;
    size_t min_stretch_samples = 4;
    /// A floor lies this far above the decay's straight continuation at the end [dB]. Commit
    /// ed5996c (5 -> 3 dB with the evidence test; tuning seeds 1000000+: clean-record Q coverage
    /// 20/40 -> 33/40); kept "as before" in 1016aed (docs/validation_ringdown.md, item 6).
    double excess_db = 3.0;
    /// The line-plus-floor model beats the straight line by this evidence [n ln(SSE_0 / SSE_1)].
    /// Commit ed5996c (same run as excess_db).
    double evidence = 30.0;
    /// Past the line's crossing of the floor the scatter of ln A about a straight line exceeds
    /// this [neper] (1.7 dB), else the bend is a slowing decay, not a floor. Noise alone
    /// (Rayleigh) has sd pi / sqrt(24) = 0.64; on tuning floors 0.38 .. 0.79, on the slowing
    /// decays 0.01 .. 0.11, beats up to 0.59 (commit 1016aed, docs/validation_ringdown.md item 6:
    /// floors claimed without one 8/240 -> 1/240, spans cut above a suspected floor 44 -> 2).
    double scatter = 0.2;
    /// Without the evidence, a floor also confirms when that scatter is this many times the one
    /// over the first half of the decay before the crossing [ratio] (the evidence alone failed
    /// where the floor's deep Rayleigh dips dominate the sums of squares; commit 1016aed, same
    /// tuning as scatter).
    double scatter_ratio = 2.0;
    /// The envelope reaches a confirmed floor within this of it [dB] (floor_start_s). Set by hand
    /// (commit 3dbfdf5), no recorded evidence.
    double reach_db = 3.0;
  };
  NoiseFloor noise_floor;

  /// Step 3: the drive switch-off and the plateau.
  struct Plateau {
    /// The plateau level is the median over the window's first head_divisor-th [1] ...
    size_t head_divisor = 20;
    /// ... at least this many samples [samples]. Both set by hand (commit bde2bb5), no recorded
    /// evidence.
    size_t min_head_samples = 5;
    /// The switch-off threshold lies max(switch_off_sd robust sd [multiples of noise_sd_log],
    /// switch_off_min_db [dB]) below the plateau. Set by hand (commit bde2bb5: drive-off from the
    /// first fall below the plateau level), no recorded evidence for the values.
    double switch_off_sd = 6.0;
    double switch_off_min_db = 0.1;
    /// For a plateau that creeps, the switch-off is read this far below it [dB] when the
    /// noise-sized threshold finds no plateau and no steady fall. Commit fe6d1d3: D060 of the
    /// real development set (0.6 dB over 1.6 s) gets its plateau; tuning 123/154 unchanged.
    double wide_switch_off_db = 1.0;
    /// The crossing is read below the head's 1 / percentile_divisor quantile [1] (20: the 5th
    /// percentile; a beating plateau dips below its median). Commit ab1f760: beat 16/19 -> 19/19
    /// on tuning base 42000000 (docs/validation_ringdown.md item 7).
    size_t percentile_divisor = 20;
    /// The decay rate after the crossing is read over an after_divisor-th of the window [1] ...
    size_t after_divisor = 20;
    /// ... at least this many samples [samples]. Both set by hand (commit bde2bb5), no recorded
    /// evidence.
    size_t min_after_samples = 8;
    /// Falling steadily: differences over a lag_divisor-th of the stretch before the crossing [1],
    /// falling_share of them negative [fraction] (a beating plateau falls and rises). Set by hand
    /// (commit faf2753, before its reporting run), no recorded evidence for the values.
    size_t lag_divisor = 10;
    double falling_share = 0.9;
    /// ... and a mean rate before the crossing of rate_ratio of the one after or more [ratio]: a
    /// record that starts inside a fast first stage has no plateau. Commit 6cee0d4: two_stage
    /// 13/20 -> 19/20 on tuning base 41000000 (the rule as a whole; no other value recorded).
    double rate_ratio = 0.3;
    /// A plateau's crossing lies past this sample [samples] ...
    size_t min_cross_index = 2;
    /// ... and later than delay times the time the decay takes to fall by the threshold [ratio].
    /// Both set by hand (commit bde2bb5), no recorded evidence.
    double delay = 3.0;
  };
  Plateau plateau;

  /// Step 3: detector settling after the drive-off.
  struct Settling {
    /// Settling is read on spans of more than this many samples [samples] ...
    size_t min_span = 40;
    /// ... within the first skip_db of decay [dB] (at most that is skipped), against the rate from
    /// there to rate_end_db [dB] over more than min_rate_samples samples. Set by hand (commit
    /// ca46f02), no recorded evidence for the values.
    double skip_db = 3.0;
    double rate_end_db = 13.0;
    size_t min_rate_samples = 8;
    /// The local rate is read over a rate_window_divisor-th of the window [1] (commit 9b14288,
    /// was 200 in ca46f02; no comparison recorded) ...
    size_t rate_window_divisor = 80;
    /// ... at least this many samples [samples] (commit ca46f02, no recorded evidence) ...
    size_t min_rate_window = 8;
    /// ... and the span starts this many times the time to the rate's peak after the drive-off
    /// [ratio] (a 2-pole filter leaves 0.25 dB after 2.5 time constants). Commit 9b14288;
    /// docs/validation_ringdown.md ("Why gamma_nl is the hard cause"): skipping half as long gave
    /// gamma_nl 23/30, gamma_a 28/30 on tuning base 41000000, worse.
    double time_factor = 2.0;
  };
  Settling settling;

  /// The longest straight stretch (ringdown_straight_span.h) correcting the span of steps 1-4
  /// (commit 3d3ff4f: tuning part 83 -> 99 of 154 clean within 5 %, the rules together; no
  /// comparison of the values below is recorded unless said).
  struct StraightSpanRules {
    /// A stretch corrects the span from this many dB of decay [dB] (commit 3d3ff4f).
    double min_correct_db = 10.0;
    /// When steps 1-4 find no decay, a stretch of this many dB or more is one [dB] (in the window,
    /// else from each drive-on stretch of the whole record; commit f7676e1: clean tuning refusals
    /// 4 -> 0, 115 -> 119 of 154).
    double min_fallback_db = 10.0;
    /// The stretch starts more than this many samples before the span's end; to end the span at
    /// a floor, its end lies more than this many samples inside the span on both sides and the
    /// level past it is read on at least this many usable samples [samples] (commit 3d3ff4f).
    size_t min_gap_samples = 8;
    /// A start on a switch-off transient: the level before the stretch dips more than this below
    /// the stretch's line extrapolated back [dB] ...
    double transient_dip_db = 3.0;
    /// ... when the stretch starts within the span's first transient_max_percent [%] (commit
    /// 3d3ff4f).
    size_t transient_max_percent = 15;
    /// A start on a creeping plateau: the level falls to the stretch at under creep_ratio of what
    /// the stretch's rate gives [ratio] (commit 3d3ff4f; docs/validation_ringdown_real.md, "What
    /// was built" item 2: "under half the decay rate").
    double creep_ratio = 0.5;
  };
  StraightSpanRules straight_span;

  /// A tail that bends into a floor nobody confirmed (docs/validation_ringdown_real.md, 28 Nov
  /// item 3; commit 2307bea: tuning part 119 -> 122 of 154 clean within 5 %, the generator's
  /// tuning base 41000000 fires on none of 210 records). The values were set with the rule; no
  /// comparison of other values is recorded.
  struct Tail {
    /// Read on spans of at least this many usable samples [samples] ...
    size_t min_samples = 60;
    /// ... smoothed by a running median of half-width a smooth_divisor-th of them [1], at least
    /// min_smooth_half samples [samples].
    size_t smooth_divisor = 60;
    int min_smooth_half = 2;
    /// Over the last quarter the level falls at under slowing_ratio of the middle half's rate
    /// [ratio] ("under half") ...
    double slowing_ratio = 0.5;
    /// ... while its sample-to-sample scatter grows over roughness_growth times the middle's
    /// [ratio] ("grows by half").
    double roughness_growth = 1.5;
    /// The tail leaves the line of the first three quarters by more than max(tolerance_db [dB],
    /// tolerance_sd times the middle's scatter) ...
    double tolerance_db = 1.5;
    double tolerance_sd = 4.0;
    /// ... for max(min_run [samples], a run_divisor-th of the samples [1]) in a row.
    size_t min_run = 3;
    size_t run_divisor = 100;
    /// The cut keeps at least this much decay, else the span stays [dB].
    double min_kept_db = 10.0;
  };
  Tail tail;

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
