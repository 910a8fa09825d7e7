// The longest straight stretch of a ring-down's level in dB (a single exponential), as a person
// reading a real export would pick it (docs/validation_ringdown.md, "Real records"):
//  1. The level is reduced to block medians (at most `grid` points) and smoothed by a running
//     median of 1/300 of them (a switch-off transient of ten samples stays visible); its robust
//     sample-to-sample sd sets the tolerance tol = max(tol_db, tol_sd sd), 4 sd by default.
//  2. From each start where the level first falls 1, 2, 3, 5, 8, 12, 17, 23, 30 or 40 dB below
//     its peak (or each of its peaks with all_peaks), the first `first_db` of fall must lie on a
//     line within tol; the line is then extended sample by sample (refitted every tenth of its
//     length) until `run` consecutive samples (1 % of the grid, at least 3) leave it by more than
//     tol.
//  3. The candidate with the largest fall in dB times the square root of its samples wins (an
//     earlier start wins ties within 5 %): a long decay, not a switch-off transient of a few
//     samples that falls as many dB.
//  4. How the stretch ends: at the record's end, at a floor (the level past the end, over 30 % of
//     the stretch, falls at under flat_fraction of the stretch's rate: a noise floor, wandering or
//     not, or a detector's smooth tail), in a slowing decay (it still falls, more slowly), or
//     falling below the line.
#pragma once

#include <string>
#include <vector>

namespace cvg_bench {

/// The tuned choices of the straight stretch. Unless said otherwise a value was set by hand with
/// the straight stretch (commit 3d3ff4f: with that commit's window changes the tuning part went
/// from 83 to 99 of 154 clean records within 5 %, generator base 41000000 206/210 right causes;
/// docs/validation_ringdown_real.md, "What was built" 2) and nothing records why that value.
struct StraightSpanOptions {
  /// Least tolerance about the line [dB] ("max(1.5 dB, 4 sd)").
  double tol_db = 1.5;
  /// The tolerance is at least this many robust sd of the block medians' own scatter [sd].
  double tol_sd = 4.0;
  /// Fall that must be straight before the line is extended [dB].
  double first_db = 5.0;
  /// That first fall spans at least this many grid steps [block medians]; a start within
  /// first_min_steps + 1 of the grid's end (and every later start) is not tried.
  int first_min_steps = 6;
  /// At most this many block medians.
  int grid = 1500;
  /// Records (and grids of block medians) under this many points have no straight stretch.
  size_t min_points = 16;
  /// The smoothing running median's half-width: a smooth_divisor-th of the grid (1/300: a
  /// switch-off transient of ten samples stays visible), at least min_smooth_half points.
  int smooth_divisor = 300;
  int min_smooth_half = 2;
  /// A line ends when `run` consecutive points leave it: a run_divisor-th of the grid (1 %), at
  /// least min_run points. The same run is the least stretch past the end read for how it ends.
  int run_divisor = 100;
  int min_run = 3;
  /// The line is refitted each time it grew by a refit_divisor-th of its length, at least
  /// min_refit points.
  int refit_divisor = 10;
  int min_refit = 3;
  /// The peak is read from a wider running median, of half-width a peak_median_divisor-th of the
  /// grid (2 %), at least min_peak_median_half points: a glitch of a few samples is no peak.
  int peak_median_divisor = 50;
  int min_peak_median_half = 3;
  /// Candidate starts: where the level first falls this far below the (each) peak [dB].
  std::vector<double> start_drops_db = {1.0, 2.0, 3.0, 5.0, 8.0, 12.0, 17.0, 23.0, 30.0, 40.0};
  /// A later candidate wins only when its score (dB times the square root of its samples) is
  /// over this many times the best so far [-]: an earlier start wins ties within 5 %.
  double tie_ratio = 1.05;
  /// How the stretch ends is read over post_tenths tenths of its length past it (30 %), at least
  /// `run` points.
  int post_tenths = 3;
  /// Past the end the level falls at under this fraction of the stretch's rate: it has met its
  /// floor (a noise floor, a wandering one, a detector's smooth tail). The generator's slowing
  /// decays keep over 0.28 of their early rate (gamma_a) and its two-stage decays' straightest
  /// stretch is the slow stage, which runs to the floor.
  double flat_fraction = 0.2;
  /// Start from every peak, not only the highest: the end of each run of the level within
  /// `peak_near_db` of the top (a record that holds several drive-on stretches, one of them
  /// followed by the decay). Used where the plateau-and-floor reading found no decay (commit
  /// f7676e1: tuning refusals 4 -> 0, clean within 5 % 115 -> 119 of 154).
  bool all_peaks = false;
  /// [dB]; set by hand (commit f7676e1), no recorded evidence.
  double peak_near_db = 3.0;
};

enum class StraightSpanEnd { kRecordEnd, kFloor, kSmoothRise, kFall };

struct StraightSpan {
  bool ok = false;
  size_t i_start = 0, i_end = 0;  ///< samples [i_start, i_end) of the input
  double slope_db_s = 0.0;        ///< of the level, negative for a decay
  double span_db = 0.0;           ///< fall along the line over the stretch
  double post_slope_db_s = 0.0;   ///< of the level past the end (over 30 % of the stretch)
  StraightSpanEnd end = StraightSpanEnd::kRecordEnd;
  std::string endName() const;
};

/// t: sample times [s]; y: ln A (NaN where not finite; skip marks samples to leave out).
StraightSpan findStraightSpan(const std::vector<double>& t, const std::vector<double>& y,
                              const std::vector<bool>& skip, const StraightSpanOptions& o = {});

}  // namespace cvg_bench
