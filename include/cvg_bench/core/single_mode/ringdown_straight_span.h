// The longest straight stretch of a ring-down's level in dB (a single exponential), as a person
// reading a real export would pick it (docs/validation_ringdown.md, "Real records"):
//  1. The level is reduced to block medians (at most `grid` points) and smoothed by a running
//     median of 1/300 of them (a switch-off transient of ten samples stays visible); its robust
//     sample-to-sample sd sets the tolerance tol = max(tol_db, 4 sd).
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

struct StraightSpanOptions {
  double tol_db = 1.5;    ///< least tolerance about the line [dB]
  double first_db = 5.0;  ///< fall that must be straight before the line is extended [dB]
  int grid = 1500;        ///< at most this many block medians
  /// Past the end the level falls at under this fraction of the stretch's rate: it has met its
  /// floor (a noise floor, a wandering one, a detector's smooth tail). The generator's slowing
  /// decays keep over 0.28 of their early rate (gamma_a) and its two-stage decays' straightest
  /// stretch is the slow stage, which runs to the floor.
  double flat_fraction = 0.2;
  /// Start from every peak, not only the highest: the end of each run of the level within
  /// `peak_near_db` of the top (a record that holds several drive-on stretches, one of them
  /// followed by the decay). Used where the plateau-and-floor reading found no decay.
  bool all_peaks = false;
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
