// The part of Q's uncertainty that comes from the span choice (docs/validation_ringdown.md,
// "Real records"): repeats of one resonator differ by a few per cent, more than the noise inside
// one record explains, and a person choosing the window by hand moves Q too. The selected model
// is refitted on four neighbouring spans (start 10 % and 20 % of the span later, end 10 % and
// 20 % earlier) and the spread of Q over the five fits is the span part:
//   std_span = sqrt(sum_k (Q_k - Q)^2 / 4),  std_total = sqrt(std^2 + std_span^2),
// and the total interval is Q exp(+-z std_total / Q) (never negative, never of zero width),
// widened to the within-record interval where that is wider (an open bound stays open).
#pragma once

#include "cvg_bench/core/single_mode/ringdown_fit.h"

namespace cvg_bench {

/// Adds std_span, std_total and the total interval to fit->derived["Q"] (and Q0 where present).
void addSpanSpread(const RingdownEnvelope& env, const RingdownSegment& seg,
                   const RingdownFitOptions& options, RingdownFit* fit);

}  // namespace cvg_bench
