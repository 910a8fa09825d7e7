// Physical sanity of an estimate, checked before every publication. A resonator that rings down
// has positive damping: gamma > 0 ((2.6), gamma = omega / Q), both principal dampings
// gamma -+ sqrt(b_c^2 + b_s^2) > 0 (section 4: gamma_max - gamma_min = 2 sqrt(b_c^2 + b_s^2)), and
// hence Q > 0. An estimate breaking these (e.g. an old and a new run fitted together), or whose
// interval for gamma or Q reaches below zero (wider than physical), or whose axis angle interval
// spans the whole period pi/2, is flagged: the problems are listed in words with units.
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/estimate/estimate.h"

namespace cvg_bench {

/// Every problem found (empty: plausible).
std::vector<std::string> sanityProblems(const Estimate& e);

}  // namespace cvg_bench
