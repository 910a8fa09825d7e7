// The value type both one-mode analyses report (ring-downs, ringdown_fit.h; frequency response,
// response_fit.h): an estimate in SI units with its standard error and confidence interval, and
// the fields only one of them fills (left at their defaults by the other).
#pragma once

#include <limits>

namespace cvg_bench {

struct OneModeValue {
  double value = 0.0, std = 0.0, ci_low = 0.0, ci_high = 0.0;
  /// Ring-downs: the Cramer-Rao standard error under white noise (0 when none).
  double crb_std = 0.0;
  /// Frequency response: degrees of freedom of the interval's Student t (0: not a t interval).
  int dof = 0;
  /// Ring-down Q and Q0 only (ringdown_span_spread.h): the span choice's part and the total; NaN
  /// unset.
  double std_span = std::numeric_limits<double>::quiet_NaN();
  double std_total = std::numeric_limits<double>::quiet_NaN();
  double ci_total_low = std::numeric_limits<double>::quiet_NaN();
  double ci_total_high = std::numeric_limits<double>::quiet_NaN();
};

using RingdownValue = OneModeValue;
using ResponseValue = OneModeValue;

}  // namespace cvg_bench
