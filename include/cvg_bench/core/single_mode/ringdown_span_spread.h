// The part of Q's uncertainty that comes from the span choice (docs/validation_ringdown.md,
// "Real records"): repeats of one resonator differ by a few per cent, more than the noise inside
// one record explains, and a person choosing the window by hand moves Q too. The selected model
// is refitted on four neighbouring spans (start 10 % and 20 % of the span later, end 10 % and
// 20 % earlier) and the spread of Q over the five fits is the span part:
//   std_span = sqrt(sum_k (Q_k - Q)^2 / 4),  std_total = sqrt(std^2 + std_span^2),
// and the total interval is Q exp(+-z std_total / Q) with z the normal quantile of the fit's
// confidence (never negative, never of zero width), widened to the within-record interval where
// that is wider (an open bound stays open). std_span divides by the neighbouring fits that gave
// every reported value (four when all fit).
#pragma once

#include <cstddef>

#include "cvg_bench/core/single_mode/ringdown_fit.h"

namespace cvg_bench {

/// The neighbouring spans and the total interval (all set by hand in commit 29389b8, which
/// recorded the tuning part 99 -> 106 of 154 for the whole change, not for these values).
struct RingdownSpanSpreadOptions {
  /// A span shorter than this has no span part [samples]. No recorded evidence.
  std::size_t min_span_samples = 20;
  /// The nearer neighbours: start, or end, moved in by this fraction of the span [1]. No
  /// recorded evidence.
  double near_cut = 0.1;
  /// The farther neighbours: start, or end, moved in by this fraction of the span [1]. No
  /// recorded evidence.
  double far_cut = 0.2;
  /// Neighbouring fits needed (of four) for a span part [1]. No recorded evidence.
  int min_fits = 3;
};

/// Adds std_span, std_total and the total interval to fit->derived["Q"] (and Q0 where present).
void addSpanSpread(const RingdownEnvelope& env, const RingdownSegment& seg,
                   const RingdownFitOptions& options, RingdownFit* fit,
                   const RingdownSpanSpreadOptions& spread = {});

}  // namespace cvg_bench
