// The sample median used across the core: the upper middle element (index n/2 after a partial
// sort), no averaging of the two middle ones for even n; one definition for every stage.
#pragma once

#include <algorithm>
#include <limits>
#include <vector>

namespace cvg_bench {

/// Standard deviation of Gaussian noise per median absolute deviation (1 / Phi^-1(3/4)): the robust
/// scale sd = kGaussianSdPerMad * median |d|.
constexpr double kGaussianSdPerMad = 1.4826;

/// Upper median of v (taken by value: it is reordered); `if_empty` for an empty v.
inline double sampleMedian(std::vector<double> v,
                           double if_empty = std::numeric_limits<double>::quiet_NaN()) {
  if (v.empty()) return if_empty;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace cvg_bench
